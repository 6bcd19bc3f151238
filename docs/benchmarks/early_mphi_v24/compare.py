"""``shaping.early_mphi=true`` against the default on the suite's shaped runs (seeds 0-9): the default's runs are
``../suite_one_version_v24/suite`` (the README table's, rerun at one code version). Per task: generations to the
threshold (censored means: an unsolved seed counts as budget + 1), seeds solved, the ratio of means with a 95%
bootstrap interval over seeds (paired), the late test reward (last 10 generations), candidates accepted, whole-run
wall time (median ratio; the two arms ran at different machine loads), and per seed (seed, early, default).
Prints JSON.

    PYTHONPATH=src python docs/benchmarks/early_mphi_v24/compare.py DIR [DIR...]"""
import csv
import json
import sys
from pathlib import Path

import numpy as np

from shaped_es.benchmark.suite import SUITES
from shaped_es.envs.thresholds import threshold_of

DEFAULT = Path(__file__).resolve().parent.parent / "suite_one_version_v24" / "suite"


def run(d: Path, thr: float, budget: int):
    f = d / "metrics.csv"
    if not f.exists():
        return None
    r = list(csv.DictReader(open(f)))
    if len(r) < budget:
        return None
    t = np.array([float(x["test_reward_mean"]) for x in r[:budget]])
    hit = np.flatnonzero(t >= thr)
    return dict(g=int(hit[0]) + 1 if hit.size else budget + 1, late=float(t[-10:].mean()),
                acc=sum(x.get("candidate_accepted") == "1" for x in r[:budget]),
                wall=float(r[budget - 1]["wall_time_s"]))


def boot(a, b, n=4000, rng=np.random.default_rng(0)):
    a, b = np.asarray(a, float), np.asarray(b, float)
    i = rng.integers(0, len(a), (n, len(a)))
    r = a[i].mean(1) / b[i].mean(1)
    return [round(float(np.percentile(r, 2.5)), 2), round(float(np.percentile(r, 97.5)), 2)]


def paired(pairs: list[tuple[int, dict, dict]], G: int) -> dict:
    """Per task, from ``(seed, early run, default run)`` summaries (:func:`run`): the module docstring's numbers."""
    gn, go = [n["g"] for _, n, _ in pairs], [o["g"] for _, _, o in pairs]
    return dict(seeds=len(pairs), early=round(float(np.mean(gn)), 2), default=round(float(np.mean(go)), 2),
                ratio=round(float(np.mean(gn) / np.mean(go)), 2), ci=boot(gn, go),
                solved=[sum(g <= G for g in gn), sum(g <= G for g in go)],
                late=[round(float(np.mean([n["late"] for _, n, _ in pairs])), 3),
                      round(float(np.mean([o["late"] for _, _, o in pairs])), 3)],
                accepted=[sum(n["acc"] for _, n, _ in pairs), sum(o["acc"] for _, _, o in pairs)],
                wall_ratio_median=round(float(np.median([n["wall"] / o["wall"] for _, n, o in pairs])), 2),
                per_seed=[(s, n["g"], o["g"]) for s, n, o in pairs])


def main(dirs: list[Path]) -> dict:
    out = {}
    for task in SUITES["waypoints"]:
        thr, G = threshold_of(task.env)[0], task.generations
        pairs = []
        for s in range(10):
            new = next((run(d / task.env / "runs" / f"shaped_s{s}", thr, G) for d in dirs
                        if (d / task.env / "runs" / f"shaped_s{s}").exists()), None)
            old = run(DEFAULT / task.env / "runs" / f"shaped_s{s}", thr, G)
            if new and old:
                pairs.append((s, new, old))
        if not pairs:
            continue
        out[task.env] = paired(pairs, G)
    full = [v for v in out.values() if v["seeds"] == 10]
    if full:
        out["geomean_ratio"] = round(float(np.exp(np.mean([np.log(v["ratio"]) for v in full]))), 3)
    return out


if __name__ == "__main__":
    json.dump(main([Path(p) for p in sys.argv[1:]]), sys.stdout, indent=1)
