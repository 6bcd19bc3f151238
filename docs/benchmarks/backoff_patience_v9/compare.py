"""The back-off's patience, 8 judged losses in a row against the default 5, at the eleventh session's code:
per task, seeds 0-9 (and ReacherWay-v0 10-19), generations to the threshold (censored mean), seeds solved,
late test reward, candidates accepted and generations awake per run; the four held-out bodies beside them.
Prints JSON.

    python docs/benchmarks/backoff_patience_v9/compare.py

Runs: ``suite/`` (patience 8, ``--set shaping.backoff_after=8``), ``reacher_10_19/patience_8`` and
``reacher_10_19/patience_5``, ``heldout/runs/BODY/patience_8``; patience 5 (the default) is
``../backoff_keep_v9``'s final-default arm (``compare.path(task, seed, "double")``), Vanilla-ES and CMA-ES
as there (ReacherWay-v0 10-19: ``../suite_waypoints_v6/seeds_10_19``).
"""

from __future__ import annotations

import contextlib
import importlib.util
import io
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    argv, sys.argv = sys.argv, sys.argv[:1]
    with contextlib.redirect_stdout(io.StringIO()):  # those modules print their own JSON when loaded
        spec.loader.exec_module(mod)
    sys.argv = argv
    return mod


v9 = _load("compare_v9", HERE.parent / "backoff_keep_v9" / "compare.py")
ho9 = _load("compare_v9_heldout", HERE.parent / "backoff_keep_v9" / "heldout" / "compare.py")
sc = v9.sc


def path(task: str, seed: int, arm: str) -> Path:
    if task == "ReacherWay-v0" and seed >= 10:
        if arm in ("vanilla", "cmaes"):
            return HERE.parent / "suite_waypoints_v6" / "seeds_10_19" / task / "runs" / f"{arm}_s{seed}" / "metrics.csv"
        return HERE / "reacher_10_19" / arm / task / "runs" / f"shaped_s{seed}" / "metrics.csv"
    if arm == "patience_8":
        top = "suite" if seed < 10 else "suite_10_19"
        return HERE / top / task / "runs" / f"shaped_s{seed}" / "metrics.csv"
    return v9.path(task, seed, "double" if arm == "patience_5" else arm)


def arm(task: str, name: str, seeds: range) -> dict | None:
    return v9.arm(task, name, seeds, path)


out, rng = {}, np.random.default_rng(0)
for task in v9.TASKS:
    res = {k: arm(task, k, range(10)) for k in ("patience_8", "patience_5", "vanilla", "cmaes")}
    for k in ("patience_8", "patience_5"):
        if res[k]:
            res[f"{k}_over_vanilla"] = v9.ratio(res[k], res["vanilla"], rng)
    if task == "ReacherWay-v0":
        res["seeds_10_19"] = {k: arm(task, k, range(10, 20)) for k in ("patience_8", "patience_5", "vanilla", "cmaes")}
    if task in ("Kart-v0", "UR5Reach-v0"):  # seeds 0-19, ratios with 95% bootstrap intervals
        both = {k: arm(task, k, range(20)) for k in ("patience_8", "patience_5", "vanilla", "cmaes")}
        res["seeds_0_19"] = {k: v for k, v in both.items() if v}
        for k in ("patience_8", "patience_5"):
            for b in ("vanilla", "cmaes"):
                if both.get(k) and both.get(b):
                    res["seeds_0_19"][f"{k}_over_{b}"] = v9.ratio(both[k], both[b], rng)
    out[task] = res
done = [t for t in v9.TASKS if out[t]["patience_8"]]
geo = lambda k: round(float(np.exp(np.mean([np.log(out[t][f"{k}_over_vanilla"][0]) for t in done]))), 3)  # noqa: E731
out["geomean_over_vanilla"] = {"tasks": done, **{k: geo(k) for k in ("patience_8", "patience_5")}}
heldout = {}
for body, thr in ho9.BODIES.items():
    heldout[body] = {}
    for name in ("patience_8", "patience_5", "vanilla"):
        paths = [HERE / "heldout" / "runs" / body / name / f"shaped_s{s}" / "metrics.csv" if name == "patience_8"
                 else ho9.path(body, "double" if name == "patience_5" else name, s) for s in range(10)]
        if all(p.exists() for p in paths):
            per = [ho9.one(p, thr) for p in paths]
            g = [x["gens"] for x in per]
            heldout[body][name] = {"solved": sum(x <= ho9.BUDGET for x in g), "gens": round(float(np.mean(g)), 1),
                                   "gens_per_seed": g, "final": round(float(np.mean([x["final"] for x in per])), 2),
                                   "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1)}
out["heldout"] = heldout
print(json.dumps(out, indent=1))
