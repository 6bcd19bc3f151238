#!/bin/bash
# corrupt.sh CASE 'shell commands run inside the copy' [BASE] [REF]
export PATH=/tmp/civenv/bin:$PATH
C=c_$1; CMDS=$2; BASE=${3:-base5}; REF=${4:-ref_pv8}
cd /work/exp/s34/audit; rm -rf $C; cp -a $BASE $C
(cd $C && eval "$CMDS")
(cd $C && find . -type f -exec sha256sum {} + | sort -k2) > logs/$C.before
shaped-es resume $C ${RESUME_ARGS} > logs/$C.resume.out 2>&1; rc=$?
echo "[$1] resume rc=$rc"
grep -E "error|warning|Traceback" logs/$C.resume.out | head -4 | cut -c1-500
(cd $C && find . -type f -exec sha256sum {} + | sort -k2) > logs/$C.after
if [ $rc -ne 0 ]; then
  if diff -q logs/$C.before logs/$C.after >/dev/null; then echo "  dir unchanged byte-for-byte"; else echo "  DIR CHANGED:"; diff logs/$C.before logs/$C.after | grep '^[<>]' | awk '{print $1,$3}' | head -8; fi
else
  python cmp.py $REF/metrics.csv $C/metrics.csv
  echo "  deleted: $(comm -23 <(awk '{print $2}' logs/$C.before) <(awk '{print $2}' logs/$C.after) | grep -v -E 'trajectories/|checkpoints/gen_00000[0-5]' | tr '\n' ' ')"
fi
