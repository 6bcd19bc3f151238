source /tmp/civenv/bin/activate
export PYTHONPATH=/work/exp/s29/src_c02534c3
for t in UR5Reach-v0:60 ReacherWay-v0:80; do
  env=${t%%:*}; g=${t##*:}
  shaped-es benchmark --env $env --methods s12 --variant s12=shaped,shaping.mean_clone.scales=[1,2] --seeds 10 --generations $g --executor inline --no-estimate --quiet --out b_$env > b_$env.log 2>&1
done
