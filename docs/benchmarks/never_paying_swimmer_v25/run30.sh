#!/bin/bash
# side by side: for each seed, Vanilla-ES then shaped, 30 generations of SwimmerWay-v0, inline; process wall time too
export PATH=/tmp/civenv/bin:$PATH PYTHONPATH=src
for s in 0 1 2 3 4 5 6 7 8 9; do
  for m in vanilla shaped; do
    t0=$(date +%s.%N)
    shaped-es train --env SwimmerWay-v0 --method $m --generations 30 --seed $s --out sw_${m}_s$s --executor inline --quiet > sw_${m}_s$s.json 2>sw_${m}_s$s.err
    t1=$(date +%s.%N)
    echo "$m $s $(echo "$t1 - $t0" | bc)" >> times.txt
  done
done
