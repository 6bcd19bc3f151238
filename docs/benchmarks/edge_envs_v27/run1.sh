#!/bin/bash
# usage: run1.sh NAME [methods] [extra train args...]   -> logs/NAME.*.log
export PATH=/tmp/civenv/bin:$PATH; export PYTHONPATH=/work/exp/s30/src:/work/exp/s30/edge
cd /work/exp/s30/edge
N=$1; M=${2:-shaped}; shift; shift
ID=edge_envs:Edge-$N-v0
{ echo "\$ shaped-es check-env $ID"; timeout 300 shaped-es check-env $ID; echo "rc=$?"; } > logs/$N.check.log 2>&1
for m in ${M//,/ }; do
  rm -rf runs/$N-$m
  { echo "\$ shaped-es train --env $ID --method $m --generations 2 --pairs 4 --executor inline --out runs/$N-$m $*"; timeout 600 shaped-es train --env $ID --method $m --generations 2 --pairs 4 --executor inline --out runs/$N-$m "$@"; echo "rc=$?"; } > logs/$N.$m.train.log 2>&1
  { echo "\$ shaped-es evaluate runs/$N-$m --episodes 3"; timeout 300 shaped-es evaluate runs/$N-$m --episodes 3; echo "rc=$?"; } > logs/$N.$m.eval.log 2>&1
done
echo "== $N"; tail -n 3 logs/$N.check.log | cut -c1-300; for m in ${M//,/ }; do grep -h -E 'error|warning|rc=|Traceback' logs/$N.$m.*.log | cut -c1-400; done
