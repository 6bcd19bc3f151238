"""The shooting labels aiming one waypoint step past the waypoint (``shoot_ahead: 1``) against aiming at it
(``0``, the eleventh session's default: ``../backoff_patience_v9``'s patience-8 runs, the same code otherwise),
per task: seeds 0-9 (the kart, UR5Reach-v0 and the Reacher also 10-19), generations to the threshold
(censored mean), seeds solved, late test reward, candidates accepted and generations awake per run, the
ratio of means to Vanilla-ES's (and CMA-ES's over 0-19) with a 95% bootstrap interval (seeds resampled in
pairs); the four held-out bodies beside them. Prints JSON.

    python docs/benchmarks/shoot_ahead_v10/compare.py > docs/benchmarks/shoot_ahead_v10/compare.json

Runs: ``suite/`` and ``suite_10_19/`` (``--set shaping.inverse_dynamics.shoot_ahead=1``),
``heldout/runs/BODY/ahead_1``.
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


p9 = _load("compare_p9", HERE.parent / "backoff_patience_v9" / "compare.py")
v9, ho9 = p9.v9, p9.ho9
ARMS = ("ahead_1", "patience_8", "vanilla", "cmaes")


def path(task: str, seed: int, arm: str) -> Path:
    if arm == "ahead_1":
        return HERE / ("suite" if seed < 10 else "suite_10_19") / task / "runs" / f"shaped_s{seed}" / "metrics.csv"
    return p9.path(task, seed, arm)


def arm(task: str, name: str, seeds: range) -> dict | None:
    return v9.arm(task, name, seeds, path)


out, rng = {}, np.random.default_rng(0)
for task in v9.TASKS:
    res = {k: arm(task, k, range(10)) for k in ARMS}
    for k in ("ahead_1", "patience_8"):
        if res[k]:
            res[f"{k}_over_vanilla"] = v9.ratio(res[k], res["vanilla"], rng)
    if task in ("Kart-v0", "UR5Reach-v0", "ReacherWay-v0"):  # seeds 0-19
        both = {k: arm(task, k, range(20)) for k in ARMS}
        res["seeds_0_19"] = {k: v for k, v in both.items() if v}
        for k in ("ahead_1", "patience_8"):
            for b in ("vanilla", "cmaes"):
                if both.get(k) and both.get(b) and np.mean(both[b]["gens_per_seed"]) > 0:
                    res["seeds_0_19"][f"{k}_over_{b}"] = v9.ratio(both[k], both[b], rng)
    out[task] = res
done = [t for t in v9.TASKS if out[t]["ahead_1"]]
geo = lambda k: round(float(np.exp(np.mean([np.log(out[t][f"{k}_over_vanilla"][0]) for t in done]))), 3)  # noqa: E731
out["geomean_over_vanilla"] = {"tasks": done, **{k: geo(k) for k in ("ahead_1", "patience_8")}}
heldout = {}
for body, thr in ho9.BODIES.items():
    heldout[body] = {}
    for name in ("ahead_1", "patience_8", "vanilla", "cmaes"):
        if name in ("ahead_1", "patience_8"):
            top = HERE if name == "ahead_1" else HERE.parent / "backoff_patience_v9"
            paths = [top / "heldout" / "runs" / body / name / f"shaped_s{s}" / "metrics.csv" for s in range(10)]
        else:
            paths = [ho9.path(body, name, s) for s in range(10)]
        if all(p.exists() for p in paths):
            per = [ho9.one(p, thr) for p in paths]
            g = [x["gens"] for x in per]
            heldout[body][name] = {"solved": sum(x <= ho9.BUDGET for x in g), "gens": round(float(np.mean(g)), 1),
                                   "gens_per_seed": g, "final": round(float(np.mean([x["final"] for x in per])), 2),
                                   "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1)}
    for k in ("ahead_1", "patience_8"):
        if heldout[body].get(k) and heldout[body].get("vanilla"):
            heldout[body][f"{k}_over_vanilla"] = v9.ratio(heldout[body][k], heldout[body]["vanilla"], rng)
out["heldout"] = heldout
print(json.dumps(out, indent=1))
