"""The README's suite table at a default: per task, the shaped runs of NEW_SUITE beside the Vanilla-ES and CMA-ES
runs of BASELINE_SUITE on the same seeds: generations to the threshold (censored means: an unsolved seed counts as
the budget + 1), seeds solved, shaped / Vanilla-ES and shaped / CMA-ES (ratios of means, 95% percentile-bootstrap
intervals, seeds resampled), the late test reward (each seed's mean over its last 10 tests; means over seeds) and
the geometric mean of the shaped / Vanilla-ES ratios. Prints Markdown, then JSON.

    PYTHONPATH=src python docs/benchmarks/noise_from_v29/table.py NEW_SUITE BASELINE_SUITE
"""
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "clone_noise_v28"))
from compare import boot, seeds_of  # noqa: E402

from shaped_es.benchmark.suite import SUITES  # noqa: E402
from shaped_es.envs.thresholds import threshold_of  # noqa: E402


def main(new: str, base: str) -> dict:
    out = {}
    for task, budget in ((t.env, t.generations) for t in SUITES["waypoints"]):
        thr = threshold_of(task)[0]
        arms = {m: seeds_of(new if m == "shaped" else base, task, m, budget, thr) for m in ("shaped", "vanilla", "cmaes")}
        seeds = sorted(arms["shaped"])
        if not seeds:
            continue
        g = {m: np.array([a[s]["g"] for s in seeds], float) for m, a in arms.items() if set(seeds) <= set(a)}
        row = {m: dict(gens=round(v.mean(), 1), solved=int((v <= budget).sum()),
                       late=round(float(np.mean([arms[m][s]["late"] for s in seeds])), 2)) for m, v in g.items()}
        row["seeds"] = seeds
        for m in ("vanilla", "cmaes"):
            if m in g:
                row[f"vs_{m}"] = round(g["shaped"].mean() / g[m].mean(), 2)
                row[f"vs_{m}_ci"] = boot(lambda i, m=m: g["shaped"][i].mean() / g[m][i].mean(), len(seeds))
        out[task] = row
    out["geomean_vs_vanilla"] = round(float(np.exp(np.mean([np.log(r["vs_vanilla"]) for r in out.values()]))), 3)
    return out


def markdown(res: dict) -> str:
    lines = ["| task | shaped | Vanilla-ES | CMA-ES | shaped / Vanilla-ES [95% CI] | shaped / CMA-ES [95% CI] | "
             "late reward (shaped / Vanilla-ES / CMA-ES) |", "|" + "---|" * 7]
    for t, r in res.items():
        if t == "geomean_vs_vanilla":
            continue
        cell = {m: f"{r[m]['gens']} ({r[m]['solved']}/{len(r['seeds'])})" if m in r else "" for m in ("shaped", "vanilla", "cmaes")}
        lines.append(f"| {t} | {cell['shaped']} | {cell['vanilla']} | {cell['cmaes']} | {r['vs_vanilla']}x {r['vs_vanilla_ci']} | "
                     + (f"{r['vs_cmaes']}x {r['vs_cmaes_ci']}" if "vs_cmaes" in r else "") + " | "
                     + " / ".join(str(r[m]["late"]) for m in ("shaped", "vanilla", "cmaes") if m in r) + " |")
    lines.append(f"\nGeometric mean of shaped / Vanilla-ES: {res['geomean_vs_vanilla']}x")
    return "\n".join(lines)


if __name__ == "__main__":
    res = main(*sys.argv[1:3])
    print(markdown(res))
    print(json.dumps(res, indent=1))
