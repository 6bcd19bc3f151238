#!/bin/sh
# Each suite task's step_change runs (SA, SB: shaped-es suite run ... --set shaping.inverse_dynamics.step_change=true)
# against the committed default runs (../noise_from_v29/F15seeds0to9), seed for seed: compare_TASK.md
#   sh compare_suite.sh /path/to/SA /path/to/SB
HERE=$(dirname "$0"); REF=$HERE/../noise_from_v29/F15seeds0to9
for spec in PointVel-v0:8.5:80 PointForce-v0:8.5:80 Unicycle-v0:8.5:50 Rover-v0:8.0:80 Kart-v0:8.0:120 \
            ReacherWay-v0:-6.5:80 SwimmerWay-v0:30:30 CarNav-v0:200:80 UR5Reach-v0:40:60; do
  task=${spec%%:*}; rest=${spec#*:}; thr=${rest%%:*}; budget=${rest#*:}
  for d in "$@"; do [ -d "$d/$task/runs" ] && new=$d/$task/runs; done
  python "$HERE/../ego_shoot_v32/compare.py" "$thr" "$budget" "$new/shaped_s" "$REF/$task/runs/shaped_s" > "$HERE/compare_$task.md"
  tail -n 1 "$HERE/compare_$task.md" | sed "s/^/$task: /"
done
