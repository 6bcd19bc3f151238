"""Per variant (NAME=GLOB of its runs' metrics.csv): generations to THRESHOLD (censored mean: unsolved = BUDGET + 1),
seeds solved, the late test reward (each seed's mean over its last 10 tests; mean over seeds with a 95% bootstrap
interval, and the IQM), the late population (train_reward_mean, last 10 generations), candidates accepted a run, the
median wall time; then each variant against the first on their common seeds: the paired late-reward difference and
the ratio of mean generations, with 95% percentile-bootstrap intervals (seeds resampled). Prints text.

    python cmp.py THRESHOLD BUDGET NAME=GLOB [NAME=GLOB ...]      (NumPy only)
"""
import csv, glob, sys, re, numpy as np
thr, budget = float(sys.argv[1]), int(sys.argv[2])
def one(f):
    r = list(csv.DictReader(open(f)))
    t = np.array([float(x["test_reward_mean"]) if x["test_reward_mean"] else np.nan for x in r])
    p = np.array([float(x["train_reward_mean"]) for x in r])
    hit = np.flatnonzero(t >= thr); g = int(hit[0]) + 1 if hit.size else budget + 1
    acc = sum(1 for x in r if x.get("candidate_accepted") == "1")
    tt = t[np.isfinite(t)]
    return g, float(tt[-10:].mean()), float(p[-10:].mean()), acc, float(r[-1]["wall_time_s"])
def iqm(x):
    x = np.sort(x); n = len(x); k = n // 4
    return x[k:n - k].mean()
def boot(x, fn, B=4000, rng=np.random.default_rng(0)):
    x = np.asarray(x); v = [fn(x[rng.integers(0, len(x), len(x))]) for _ in range(B)]
    return np.percentile(v, [2.5, 97.5])
res = {}
for a in sys.argv[3:]:
    name, pat = a.split("=", 1)
    fs = sorted(glob.glob(pat))
    d = {int(re.search(r"_s(\d+)/metrics.csv$", f).group(1)): one(f) for f in fs}
    res[name] = d
    seeds = sorted(d); G = np.array([d[s][0] for s in seeds]); L = np.array([d[s][1] for s in seeds])
    lo, hi = boot(L, np.mean)
    print(f"{name:10s} n={len(seeds)} gens {G.mean():5.1f} solved {(G<=budget).sum()} late mean {L.mean():6.2f} [{lo:.1f},{hi:.1f}] IQM {iqm(L):6.2f} pop {np.mean([d[s][2] for s in seeds]):6.1f} acc {np.mean([d[s][3] for s in seeds]):5.1f} wall {np.median([d[s][4] for s in seeds]):5.0f}")
    print("   per seed late", " ".join(f"{s}:{d[s][1]:.0f}/{d[s][0]}" for s in seeds))
names = list(res)
if len(names) >= 2:
    b = res[names[0]]
    for n in names[1:]:
        common = sorted(set(b) & set(res[n]))
        dl = np.array([res[n][s][1] - b[s][1] for s in common])
        gr = np.array([res[n][s][0] for s in common]) ; gb = np.array([b[s][0] for s in common])
        rng = np.random.default_rng(1); bs = [ (lambda i: gr[i].mean()/gb[i].mean())(rng.integers(0,len(common),len(common))) for _ in range(4000)]
        lo, hi = boot(dl, np.mean)
        print(f"{n} vs {names[0]} on {len(common)} seeds: late diff {dl.mean():+.2f} [{lo:+.1f},{hi:+.1f}]; gens ratio {gr.mean()/gb.mean():.2f} [{np.percentile(bs,2.5):.2f},{np.percentile(bs,97.5):.2f}]")
