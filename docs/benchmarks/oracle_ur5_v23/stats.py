"""UR5Reach-v0 with the controller's labels (the oracle), 10 seeds, jumps undone (rp3, the default margin 3) or
not (rp0): generations to the threshold 40 (censored: budget + 1), late test reward (last 10 generations),
candidates accepted, jumps undone; per seed and the means. Prints JSON.   python stats.py"""
import csv, json
from pathlib import Path
import numpy as np
HERE, THR, BUDGET = Path(__file__).parent, 40.0, 60
out = {}
for arm in ("rp3", "rp0"):
    rows = []
    for s in range(10):
        r = list(csv.DictReader(open(HERE / arm / f"shaped_s{s}" / "metrics.csv")))
        t = np.array([float(x["test_reward_mean"]) for x in r])
        hit = np.flatnonzero(t >= THR)
        rows.append(dict(seed=s, generations=int(hit[0]) + 1 if hit.size else BUDGET + 1, late=round(float(t[-10:].mean()), 2),
                         accepted=sum(x["candidate_accepted"] == "1" for x in r),
                         undone=sum(x.get("jump_reverted") == "1" for x in r)))
    out[arm] = dict(generations=float(np.mean([x["generations"] for x in rows])),
                    late=round(float(np.mean([x["late"] for x in rows])), 2), solved=sum(x["generations"] <= BUDGET for x in rows),
                    undone=sum(x["undone"] for x in rows), per_seed=rows)
print(json.dumps(out, indent=1))
