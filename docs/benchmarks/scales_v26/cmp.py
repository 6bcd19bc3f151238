"""A variant's runs against the committed default's (suite_one_version_v24), same seeds: generations to the
threshold (censored: budget + 1), late reward (mean of the last 10 tests), accepted candidates."""
import csv, glob, os, sys
import numpy as np

BASE = "../suite_one_version_v24/suite"  # the default's committed runs, seeds 0-9 (run from this folder)

def stats(run, thr):
    rows = list(csv.DictReader(open(f"{run}/metrics.csv")))
    hit = next((int(r["generation"]) + 1 for r in rows if float(r["test_reward_mean"]) >= thr), None)
    late = float(np.mean([float(r["test_reward_mean"]) for r in rows[-10:]]))
    acc = sum(r.get("candidate_accepted") == "1" for r in rows)
    return (len(rows) + 1 if hit is None else hit), hit is not None, late, acc, len(rows)

env, thr, var = sys.argv[1], float(sys.argv[2]), sys.argv[3]
A, B = [], []
for s in range(10):
    a, b = f"{var}/runs/{os.path.basename(glob.glob(f'{var}/runs/*_s{s}')[0])}" if glob.glob(f"{var}/runs/*_s{s}") else None, f"{BASE}/{env}/runs/shaped_s{s}"
    if a is None or not os.path.exists(f"{a}/metrics.csv"):
        continue
    sa, sb = stats(a, thr), stats(b, thr)
    if sa[4] < sb[4]:
        continue  # unfinished
    A.append(sa); B.append(sb)
    print(f"seed {s}: variant {sa[0]:3d} late {sa[2]:7.2f} acc {sa[3]:3d} | default {sb[0]:3d} late {sb[2]:7.2f} acc {sb[3]:3d}")
A, B = np.array(A, float), np.array(B, float)
if len(A):
    print(f"n={len(A)}: generations {A[:,0].mean():.1f} ({int(A[:,1].sum())} solved) vs {B[:,0].mean():.1f} ({int(B[:,1].sum())}); "
          f"ratio {A[:,0].mean()/B[:,0].mean():.2f}; late {A[:,2].mean():.2f} vs {B[:,2].mean():.2f}; accepted {A[:,3].mean():.1f} vs {B[:,3].mean():.1f}")
