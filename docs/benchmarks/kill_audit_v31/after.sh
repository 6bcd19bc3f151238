#!/bin/bash
# usage: after.sh NAME REF  (inspect, resume, compare)
export PATH=/tmp/civenv/bin:$PATH
NAME=$1; REF=$2; cd /work/exp/s34/audit
echo "--- state:"; ls -A $NAME | tr '\n' ' '; echo; ls -A $NAME/checkpoints 2>/dev/null | tr '\n' ' '; echo
[ -f $NAME/metrics.csv ] && echo "metrics rows: $(($(wc -l < $NAME/metrics.csv)-1))"
find $NAME -type f | sort > logs/$NAME.files_after_kill
shaped-es resume $NAME ${RESUME_ARGS} > logs/$NAME.resume.out 2>&1
echo "resume rc=$?"; grep -E "error|warning|Traceback" logs/$NAME.resume.out | head -5 | cut -c1-400
python cmp.py $REF/metrics.csv $NAME/metrics.csv
