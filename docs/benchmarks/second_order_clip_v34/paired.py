"""Two arms' runs, seed for seed (each its own benchmark folder), cut at generation G: generations to each bar
(censored at G + 1), the ratio of their means with a paired 95% percentile bootstrap (10,000 resamples, seed 0),
seeds solved, and the late test reward (the last 10 generations' mean per run) as an IQM over seeds.
    python paired.py G NEW_DIR NEW_METHOD REF_DIR REF_METHOD BAR [BAR ...] [--seeds A-B]   (default 0-9)"""
import csv
import sys

import numpy as np
from scipy.stats import trim_mean

args = sys.argv[1:]
first, last = 0, 9
if "--seeds" in args:
    i = args.index("--seeds")
    first, last = (int(x) for x in args[i + 1].split("-"))
    del args[i:i + 2]
gens, new_dir, new, ref_dir, ref = int(args[0]), *args[1:5]
bars = [float(b) for b in args[5:]]
seeds = range(first, last + 1)


def rows(root, method, seed):
    return [r for r in csv.DictReader(open(f"{root}/runs/{method}_s{seed}/metrics.csv"))
            if int(r["generation"]) < gens and r["test_reward_mean"]]


def first(root, method, seed, bar):
    hit = [int(r["generation"]) + 1 for r in rows(root, method, seed) if float(r["test_reward_mean"]) >= bar]
    return hit[0] if hit else gens + 1


def late(root, method, seed):
    return np.mean([float(r["test_reward_mean"]) for r in rows(root, method, seed)[-10:]])


rng = np.random.default_rng(0)
idx = rng.integers(0, len(seeds), size=(10_000, len(seeds)))
for bar in bars:
    a = np.array([first(new_dir, new, s, bar) for s in seeds])
    b = np.array([first(ref_dir, ref, s, bar) for s in seeds])
    r = a[idx].mean(1) / b[idx].mean(1)
    print(f"bar {bar:g}: {new} {a.mean():.1f} ({(a <= gens).sum()}/{len(seeds)}) against {ref} {b.mean():.1f} "
          f"({(b <= gens).sum()}/{len(seeds)}): {a.mean() / b.mean():.2f}x [{np.percentile(r, 2.5):.2f}, "
          f"{np.percentile(r, 97.5):.2f}]   per seed {a.tolist()} against {b.tolist()}")
la = np.array([late(new_dir, new, s) for s in seeds])
lb = np.array([late(ref_dir, ref, s) for s in seeds])
d = (la - lb)[idx].mean(1)
print(f"late (last 10 generations) IQM {trim_mean(la, 0.25):.2f} against {trim_mean(lb, 0.25):.2f}; mean paired "
      f"difference {np.mean(la - lb):+.2f} [{np.percentile(d, 2.5):+.2f}, {np.percentile(d, 97.5):+.2f}]")
