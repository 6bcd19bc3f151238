"""Each method's complete runs cut at generation 40: seeds reaching the threshold, censored mean generations to it, and the
IQM over seeds of the mean test reward of generations 31-40.   python table40.py BENCH_DIR THRESHOLD"""
import csv, glob, sys
import numpy as np
from scipy.stats import trim_mean

root, thr = sys.argv[1], float(sys.argv[2])
methods = sorted({p.split("/")[-1].rsplit("_s", 1)[0] for p in glob.glob(f"{root}/runs/*_s*")})
for m in methods:
    gens, late = [], []
    for f in sorted(glob.glob(f"{root}/runs/{m}_s*/metrics.csv")):
        rows = [r for r in csv.DictReader(open(f)) if int(r["generation"]) < 40]
        if len(rows) < 40:  # a run stopped early (killed): left out
            continue
        test = [(int(r["generation"]), float(r["test_reward_mean"])) for r in rows if r["test_reward_mean"] not in ("", None)]
        hit = [g + 1 for g, t in test if t >= thr]
        gens.append(hit[0] if hit else 41)
        late.append(np.mean([t for g, t in test if g >= 30]))
    g = np.array(gens)
    print(f"{m:8s} {int((g <= 40).sum())}/{len(g)} reached {thr:g} by 40; censored mean {g.mean():.1f}; "
          f"late (31-40) IQM {trim_mean(late, 0.25):.2f}")
