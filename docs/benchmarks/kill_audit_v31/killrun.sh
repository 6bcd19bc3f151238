#!/bin/bash
# usage: killrun.sh NAME T SIG REF GENS [extra train args...]
export PATH=/tmp/civenv/bin:$PATH
NAME=$1; T=$2; SIG=$3; REF=$4; GENS=$5; shift 5
cd /work/exp/s34/audit
rm -rf $NAME; mkdir -p logs
timeout -s $SIG $T shaped-es train --env ${ENV:-PointVel-v0} --method ${METHOD:-shaped} --generations $GENS --seed ${SEED:-3} --out $NAME --executor ${EXEC:-inline} --set tensorboard=false "$@" > logs/$NAME.train.out 2>&1
echo "train rc=$?" 
tail -3 logs/$NAME.train.out
echo "--- state after kill:"; ls -A $NAME 2>/dev/null | tr '\n' ' '; echo; ls -A $NAME/checkpoints 2>/dev/null | tr '\n' ' '; echo
[ -f $NAME/metrics.csv ] && echo "metrics rows: $(($(wc -l < $NAME/metrics.csv)-1)); last bytes: $(tail -c 40 $NAME/metrics.csv | od -c | tail -2 | head -1)"
find $NAME -type f | sort > logs/$NAME.files_after_kill
shaped-es resume $NAME ${RESUME_ARGS} > logs/$NAME.resume.out 2>&1
echo "resume rc=$?"; grep -E "error|warning|Traceback" logs/$NAME.resume.out | head -5 | cut -c1-400
python cmp.py $REF/metrics.csv $NAME/metrics.csv
