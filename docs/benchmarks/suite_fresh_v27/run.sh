#!/bin/bash
# fresh seeds 200-209 of the whole suite at commit 3c4dfa20 (src frozen in /work/exp/s30/src)
export PATH=/tmp/civenv/bin:$PATH PYTHONPATH=/work/exp/s30/src
shaped-es suite run --out suite --first-seed 200 --methods shaped,vanilla --executor inline --quiet
shaped-es suite run --out suite --first-seed 200 --methods cmaes --tasks ReacherWay-v0,UR5Reach-v0,SwimmerWay-v0 --executor inline --quiet
