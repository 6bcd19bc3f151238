"""The mean's clone fitted under the search's parameter noise (``shaping.mean_clone.noise=1``) against the default
before it (``noise=0``): per suite task, generations to the threshold (censored means: an unsolved seed counts as
budget + 1), seeds solved, new / before with a 95% percentile-bootstrap interval of the ratio of means (seeds
resampled in pairs), the late test reward (each seed's mean over its last 10 tests) and its paired difference
with an interval, the late population mean (the training returns around the mean, last 10 generations),
candidates accepted a run, and the baselines' generations and late reward beside them. Prints Markdown, then JSON.

    PYTHONPATH=src python docs/benchmarks/clone_noise_v28/compare.py NEW_SUITE[,NEW_SUITE2] BEFORE_SUITE BASELINE_SUITE
"""
import csv
import json
import sys
from pathlib import Path

import numpy as np

from shaped_es.benchmark.suite import SUITES
from shaped_es.envs.thresholds import threshold_of


def run(d: Path, budget: int, thr: float):
    f = d / "metrics.csv"
    if not f.exists():
        return None
    r = list(csv.DictReader(open(f)))[:budget]
    if len(r) < budget:
        return None
    t = np.array([float(x["test_reward_mean"]) for x in r])
    hit = np.flatnonzero(t >= thr)
    return dict(g=int(hit[0]) + 1 if hit.size else budget + 1, late=float(t[-10:].mean()),
                pop=float(np.mean([float(x["train_reward_mean"]) for x in r[-10:]])),
                acc=sum(x.get("candidate_accepted") == "1" for x in r))


def seeds_of(root: Path, task: str, method: str, budget: int, thr: float) -> dict:
    out = {}
    roots = [Path(p) for p in str(root).split(",")]  # several suite folders of one study (run side by side)
    for d in sorted(d for r in roots for d in (r / task / "runs").glob(f"{method}_s*")):
        s = run(d, budget, thr)
        if s is not None:
            out[int(d.name.split("_s")[-1])] = s
    return out


def boot(fn, n: int, reps=4000, rng=None):
    rng = rng or np.random.default_rng(0)
    v = [fn(rng.integers(0, n, n)) for _ in range(reps)]
    return [round(float(np.percentile(v, 2.5)), 2), round(float(np.percentile(v, 97.5)), 2)]


def main(new: str, before: str, base: str) -> dict:
    out = {}
    for task, budget in ((t.env, t.generations) for t in SUITES["waypoints"]):
        thr = threshold_of(task)[0]
        a, b = seeds_of(new, task, "shaped", budget, thr), seeds_of(before, task, "shaped", budget, thr)
        common = sorted(set(a) & set(b))
        if not common:
            continue
        ga, gb = np.array([a[s]["g"] for s in common], float), np.array([b[s]["g"] for s in common], float)
        la, lb = np.array([a[s]["late"] for s in common]), np.array([b[s]["late"] for s in common])
        row = dict(seeds=common, gens=[round(ga.mean(), 1), round(gb.mean(), 1)],
                   solved=[int((ga <= budget).sum()), int((gb <= budget).sum())],
                   ratio=round(ga.mean() / gb.mean(), 2), ratio_ci=boot(lambda i: ga[i].mean() / gb[i].mean(), len(common)),
                   late=[round(la.mean(), 2), round(lb.mean(), 2)], late_diff=round(float((la - lb).mean()), 2),
                   late_diff_ci=boot(lambda i: (la - lb)[i].mean(), len(common)),
                   pop=[round(np.mean([a[s]["pop"] for s in common]), 2), round(np.mean([b[s]["pop"] for s in common]), 2)],
                   accepted=[round(np.mean([a[s]["acc"] for s in common]), 1), round(np.mean([b[s]["acc"] for s in common]), 1)],
                   per_seed={s: [a[s]["g"], b[s]["g"], round(a[s]["late"], 1), round(b[s]["late"], 1)] for s in common})
        for m in ("vanilla", "cmaes"):
            c = seeds_of(base, task, m, budget, thr)
            if c:
                gc = np.array([c[s]["g"] for s in common if s in c], float)
                row[m] = dict(gens=round(gc.mean(), 1), solved=int((gc <= budget).sum()),
                              late=round(np.mean([c[s]["late"] for s in common if s in c]), 2))
        out[task] = row
    return out


def markdown(res: dict) -> str:
    lines = ["| task | noise 1 (solved) | noise 0 (solved) | ratio [95% CI] | late reward noise 1 / 0 | difference [95% CI] "
             "| late population 1 / 0 | accepted a run 1 / 0 | Vanilla-ES | CMA-ES |", "|" + "---|" * 10]
    for t, r in res.items():
        v, c = r.get("vanilla", {}), r.get("cmaes", {})
        lines.append(f"| {t} | {r['gens'][0]} ({r['solved'][0]}) | {r['gens'][1]} ({r['solved'][1]}) | {r['ratio']}x "
                     f"{r['ratio_ci']} | {r['late'][0]} / {r['late'][1]} | {r['late_diff']:+} {r['late_diff_ci']} | "
                     f"{r['pop'][0]} / {r['pop'][1]} | {r['accepted'][0]} / {r['accepted'][1]} | "
                     + (f"{v['gens']} ({v['solved']}), {v['late']}" if v else "") + " | "
                     + (f"{c['gens']} ({c['solved']}), {c['late']}" if c else "") + " |")
    g = [r["ratio"] for r in res.values()]
    lines.append(f"\nGeometric mean of the generation ratios: {float(np.exp(np.mean(np.log(g)))):.3f} over {len(g)} tasks")
    return "\n".join(lines)


if __name__ == "__main__":
    res = main(*sys.argv[1:4])
    print(markdown(res))
    print(json.dumps(res, indent=1))
