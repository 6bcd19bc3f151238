"""Which probes decide differently with 32 steps probed (the new default, ``extra`` {}) than with (8, 16) (``extra``
{"shoot_probe_horizons": [8, 16]}): ``new_vs_old.jsonl`` (``probe_run.py`` on the held-out bodies and the Reacher's
seeds 10-19). A probe that decides the same gives a run that is the previous default's to the last digit.

    python decisions.py new_vs_old.jsonl
"""

import json
import sys

FIELDS = ["frame", "clip", "chunk", "shoot_on", "horizon", "candidate", "unjudged", "third", "base"]

rows = [json.loads(line) for line in open(sys.argv[1])]
new = {(r["env"], r["seed"]): r for r in rows if not r.get("extra")}
old = {(r["env"], r["seed"]): r for r in rows if r.get("extra")}
for key, o in sorted(old.items()):
    n = new[key]
    diff = {f: (o[f], n[f]) for f in FIELDS if n[f] != o[f]}
    print(key[0], key[1], "CHANGED" if diff else "same", diff if diff else "")
