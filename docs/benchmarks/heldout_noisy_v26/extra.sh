#!/bin/bash
# extra studies, one benchmark at a time
set -x
time shaped-es benchmark --env noisy_bodies:SlipDrive-v0 --methods ctrl --variant ctrl=shaped,shaping.labels=controller --seeds 5 --generations 40 --executor inline --no-estimate --quiet --out extra_slip_ctrl
time shaped-es benchmark --env noisy_bodies:SlipDrive-v0 --methods shaped,vanilla --set env_kwargs.slip_lo=1.0 --set env_kwargs.heading_std=0.0 --seeds 5 --generations 40 --executor inline --no-estimate --quiet --out extra_slip_clean
time shaped-es benchmark --env noisy_bodies:NoisyPoint-v0 --methods shaped,vanilla --set env_kwargs.noise_scale=2.0 --threshold 6.2 --seeds 5 --generations 40 --executor inline --no-estimate --quiet --out extra_point_x2
