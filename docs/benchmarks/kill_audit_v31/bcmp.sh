#!/bin/bash
# bcmp.sh REF GOT
for r in $(ls $1/runs); do echo -n "$r: "; python cmp.py $1/runs/$r/metrics.csv $2/runs/$r/metrics.csv | tail -1; done
python - "$1" "$2" <<'PY'
import json,sys
def flat(d,p=""):
    out={}
    if isinstance(d,dict):
        for k,v in d.items(): out.update(flat(v,p+"/"+str(k)))
    elif isinstance(d,list):
        for i,v in enumerate(d): out.update(flat(v,p+f"[{i}]"))
    else: out[p]=d
    return out
a=flat(json.load(open(sys.argv[1]+"/summary.json"))); b=flat(json.load(open(sys.argv[2]+"/summary.json")))
tw=lambda k: any(s in k.lower() for s in ("time","wall","cpu","_s/","seconds","created","path","dir","report","out"))
d=[k for k in sorted(set(a)|set(b)) if not tw(k) and a.get(k)!=b.get(k)]
print("summary.json non-time diffs:", len(d)); [print("  ",k,a.get(k),"|",b.get(k)) for k in d[:15]]
PY
diff <(sed "s#$1#X#g" $1/report.md) <(sed "s#$2#X#g" $2/report.md) | grep '^[<>]' | head -20
