#!/bin/bash
export PATH=/tmp/civenv/bin:$PATH PYTHONPATH=/work/exp/s31/v28/src:/work/main/docs/benchmarks/heldout_gravarm_v24
cd /work/exp/s31/heldout
/usr/bin/time -v shaped-es benchmark --env gravarm:GravArm-v0 --variant noise1=shaped --variant noise0=shaped,shaping.mean_clone.noise=0 --methods noise1,noise0 --seeds 10 --generations 40 --threshold -80 --executor inline --quiet --no-estimate --out /work/exp/s31/heldout/gravarm
