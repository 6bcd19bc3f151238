#!/bin/bash
export PATH=/tmp/civenv/bin:$PATH PYTHONPATH=src
for s in 0 1 2 3 4 5 6 7 8 9; do
  for m in vanilla shaped; do
    shaped-es resume sw_${m}_s$s --generations 60 --quiet > /dev/null 2>>resume.err
  done
done
