"""Generations to a threshold (censored at the budget + 1) per method, from each run's metrics.csv, at several
thresholds, with a percentile-bootstrap 95% interval of the ratio of censored means (shaped / vanilla)."""
import csv, glob, sys
import numpy as np

def gens(run, thr):
    rows = list(csv.DictReader(open(f"{run}/metrics.csv")))
    hit = next((int(r["generation"]) for r in rows if float(r["test_reward_mean"]) >= thr), None)
    return (len(rows) + 1 if hit is None else hit + 1), hit is not None  # generations run to it, as the report counts

def late(run):
    rows = list(csv.DictReader(open(f"{run}/metrics.csv")))
    return float(np.mean([float(r["test_reward_mean"]) for r in rows[-10:]]))

bench = sys.argv[1]
for thr in map(float, sys.argv[2:]):
    out = {}
    for m in ("shaped", "vanilla"):
        g = [gens(r, thr) for r in sorted(glob.glob(f"{bench}/runs/{m}_s*"))]
        out[m] = (np.array([x for x, _ in g], float), sum(s for _, s in g))
    rng = np.random.default_rng(0)
    a, b = out["shaped"][0], out["vanilla"][0]
    boot = [rng.choice(a, a.size).mean() / rng.choice(b, b.size).mean() for _ in range(2000)]
    print(f"threshold {thr}: shaped {a.mean():.1f} ({out['shaped'][1]}/10), vanilla {b.mean():.1f} "
          f"({out['vanilla'][1]}/10), ratio {a.mean() / b.mean():.2f}x [{np.percentile(boot, 2.5):.2f}, "
          f"{np.percentile(boot, 97.5):.2f}]")
for m in ("shaped", "vanilla"):
    L = [late(r) for r in sorted(glob.glob(f"{bench}/runs/{m}_s*"))]
    print(m, "late reward (last 10 tests) mean", round(float(np.mean(L)), 2))
