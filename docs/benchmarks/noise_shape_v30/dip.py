"""Each seed's mean test reward over generations [A, B) (0-based rows of metrics.csv), for several sets of runs
(comma-separated globs each, seeds read from ``_s<digits>/metrics.csv``); every set after the first is compared
with the first, paired by seed: the mean difference and a 95% percentile-bootstrap interval (4000 resamples).

    python dip.py 15 35 base="A/*/runs/shaped_s*/metrics.csv,B/..." other="..."
"""
import csv
import glob
import re
import sys

import numpy as np


def load(pattern: str) -> dict[int, float]:
    out = {}
    for f in glob.glob(pattern):
        seed = int(re.search(r"_s(\d+)/metrics.csv$", f).group(1))
        rows = list(csv.DictReader(open(f)))[A:B]
        tests = [float(r["test_reward_mean"]) for r in rows if r["test_reward_mean"] not in ("", "nan")]
        out[seed] = float(np.mean(tests))
    return out


A, B = int(sys.argv[1]), int(sys.argv[2])
base = None
for arg in sys.argv[3:]:
    name, globs = arg.split("=", 1)
    per_seed = {}
    for g in globs.split(","):
        per_seed.update(load(g))
    if base is None:
        base = (name, per_seed)
        print(f"{name}: {np.mean(list(per_seed.values())):.2f} (n={len(per_seed)})")
        continue
    seeds = sorted(set(per_seed) & set(base[1]))
    diff = np.array([per_seed[s] - base[1][s] for s in seeds])  # (S,) paired by seed
    rng = np.random.default_rng(0)
    boot = [rng.choice(diff, diff.size).mean() for _ in range(4000)]
    print(f"{name}: {np.mean([per_seed[s] for s in seeds]):.2f} (n={len(seeds)}) vs {base[0]}: {diff.mean():+.2f} "
          f"[{np.percentile(boot, 2.5):+.1f}, {np.percentile(boot, 97.5):+.1f}]")
