"""Two methods' runs of one benchmark, seed for seed, cut at generation 40: generations to each bar (censored at 41)
and the ratio of their means with a paired 95% percentile bootstrap (10,000 resamples, seed 0).
    python paired40.py BENCH_DIR NEW REF BAR [BAR ...]"""
import csv, sys
import numpy as np

root, new, ref, bars = sys.argv[1], sys.argv[2], sys.argv[3], [float(b) for b in sys.argv[4:]]


def first(method, seed, bar):
    rows = [r for r in csv.DictReader(open(f"{root}/runs/{method}_s{seed}/metrics.csv")) if int(r["generation"]) < 40]
    hit = [int(r["generation"]) + 1 for r in rows if r["test_reward_mean"] and float(r["test_reward_mean"]) >= bar]
    return hit[0] if hit else 41


rng = np.random.default_rng(0)
idx = rng.integers(0, 10, size=(10_000, 10))
for bar in bars:
    a = np.array([first(new, s, bar) for s in range(10)]); b = np.array([first(ref, s, bar) for s in range(10)])
    r = a[idx].mean(1) / b[idx].mean(1)
    print(f"bar {bar:g}: {new} {a.mean():.1f} ({(a <= 40).sum()}/10) against {ref} {b.mean():.1f} ({(b <= 40).sum()}/10): "
          f"{a.mean() / b.mean():.2f}x [{np.percentile(r, 2.5):.2f}, {np.percentile(r, 97.5):.2f}]")
