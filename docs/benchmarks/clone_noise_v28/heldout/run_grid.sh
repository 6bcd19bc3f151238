#!/bin/bash
export PATH=/tmp/civenv/bin:$PATH PYTHONPATH=/work/exp/s31/v28/src:/work/main/docs/benchmarks/heldout_discrete_v25
cd /work/exp/s31/heldout
shaped-es benchmark --env gridpoint:GridPoint-v0 --variant noise1=shaped --variant noise0=shaped,shaping.mean_clone.noise=0 --methods noise1,noise0 --seeds 10 --generations 150 --threshold 10.0 --executor inline --quiet --no-estimate --out /work/exp/s31/heldout/grid
