"""The eleventh session's table: the whole suite run again at one code version (the final default, whose
back-off keeps its sleeps short while the labels win 1 judgement in 5: ``shaping.backoff_keep_rate`` 0.2)
against the same code with the old doubling (``backoff_keep_rate=0``), Vanilla-ES and CMA-ES. Per task,
seeds 0-9 (and 10-19 on Kart-v0 and UR5Reach-v0): generations to the threshold (censored mean), seeds
solved, late test reward, candidates accepted per run. Prints JSON.

    python docs/benchmarks/backoff_keep_v9/compare.py

Where the runs are (``runs`` copied with ``config.yaml``, ``metrics.csv``, ``label_probe.json``):
- ``suite/`` and ``suite_10_19/``: every seed at the final default (``shaped-es suite run --methods shaped``);
- ``double/``: the seeds whose back-off schedule would differ with ``backoff_keep_rate=0``, run again with
  it (``replay.py`` finds them from the runs' own judgements: the two schedules agree on every other seed,
  generation for generation, so its final-default run stands for it);
- Vanilla-ES and CMA-ES: ``../suite_waypoints_v6`` and ``../suite_bodies_v7`` (those runs reproduce at this
  code to the last digit: checked on UR5Reach-v0 seed 5);
- ``v8``: the table the tenth session published (``../shoot_horizon_v8/compare.py``), whose seeds of
  Reacher, swimmer, CarNav-v0 and UR5Reach-v0 partly stood in from older code (see README).
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
spec = importlib.util.spec_from_file_location("compare_v8", HERE.parent / "shoot_horizon_v8" / "compare.py")
v8 = importlib.util.module_from_spec(spec)
argv, sys.argv = sys.argv, sys.argv[:1]
with contextlib.redirect_stdout(io.StringIO()):  # v8's module prints its own JSON when loaded
    spec.loader.exec_module(v8)
sys.argv = argv
v7, sc = v8.v7, v8.sc
TASKS = v7.TASKS


def path(task: str, seed: int, arm: str) -> Path:
    """``arm``: keep (the final default), double (keep_rate 0), vanilla, cmaes."""
    top = "suite" if seed < 10 else "suite_10_19"
    if arm in ("keep", "double"):
        p = HERE / "double" / task / "runs" / f"shaped_s{seed}" / "metrics.csv"
        return p if arm == "double" and p.exists() else HERE / top / task / "runs" / f"shaped_s{seed}" / "metrics.csv"
    if seed < 10:
        return v7.runs(task, arm)[seed]
    base = HERE.parent / ("suite_waypoints_v6/seeds_10_19" if task == "UR5Reach-v0" else "shoot_horizon_v8/v7_10_19")
    return base / task / "runs" / f"{arm}_s{seed}" / "metrics.csv"


def arm(task: str, name: str, seeds: range, where=None) -> dict | None:
    """One arm's runs of one task over ``seeds`` (None: some missing); ``where(task, seed, name)``: the run's
    metrics.csv (default :func:`path`; ``../backoff_patience_v9/compare.py`` passes its own)."""
    if name == "v8" and where is None:
        paths = [v8.runs(task, "suite")[s] for s in seeds]
    else:
        paths = [(where or path)(task, s, name) for s in seeds]
    if not all(p.exists() for p in paths):
        return None
    per = [sc.one(p, sc.THRESHOLDS[task], sc.BUDGET[task]) for p in paths]
    g = np.array([x["gens"] for x in per])  # (S,)
    return {"solved": int((g <= sc.BUDGET[task]).sum()), "gens": round(float(g.mean()), 1), "gens_per_seed": g.tolist(),
            "late": round(float(np.mean([x["late"] for x in per])), 2),
            "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1),
            "awake_per_run": round(float(np.mean([x["awake"] for x in per])), 1)}


def ratio(a: dict, b: dict, rng) -> list[float]:
    """Ratio of mean generations a / b, with a 95% bootstrap interval (seeds resampled in pairs)."""
    x, y = np.array(a["gens_per_seed"], float), np.array(b["gens_per_seed"], float)
    boot = [x[i].mean() / y[i].mean() for i in (rng.integers(0, x.size, x.size) for _ in range(4000))]
    return [round(x.mean() / y.mean(), 3), *np.percentile(boot, [2.5, 97.5]).round(2).tolist()]


out, rng = {}, np.random.default_rng(0)
for task in TASKS:
    res = {k: arm(task, k, range(10)) for k in ("keep", "double", "v8", "vanilla", "cmaes")}
    res["double_seeds"] = sorted(int(p.parent.name.split("_s")[-1])
                                 for p in (HERE / "double" / task).glob("runs/shaped_s*/metrics.csv"))
    for k in ("keep", "double"):
        res[f"{k}_over_vanilla"] = ratio(res[k], res["vanilla"], rng)
    if task in ("Kart-v0", "UR5Reach-v0"):
        both = {k: arm(task, k, range(20)) for k in ("keep", "double", "vanilla", "cmaes")}
        res["seeds_0_19"] = {**{k: v for k, v in both.items() if v}}
        for k in ("keep", "double"):
            for b in ("vanilla", "cmaes"):
                if both.get(b) and both.get(k):
                    res["seeds_0_19"][f"{k}_over_{b}"] = ratio(both[k], both[b], rng)
    out[task] = res
geo = lambda k: round(float(np.exp(np.mean([np.log(out[t][f"{k}_over_vanilla"][0]) for t in TASKS]))), 3)  # noqa: E731
out["geomean_over_vanilla"] = {k: geo(k) for k in ("keep", "double")}
print(json.dumps(out, indent=1))
