"""The tenth session's table: per task, the default with the shooting rival at its fixed 4-step horizon
(``../suite_bodies_v7``'s "with" arm) against the default whose label probe also tries 8 and 16 steps, 10
seeds (0-9): generations to the threshold (censored mean), seeds solved, late test reward, candidates
accepted. Prints JSON.

    python docs/benchmarks/shoot_horizon_v8/compare.py

Where the runs are: a seed whose probe chose the 4-step horizon and kept or dropped the rival as before
runs the code path of ``../suite_bodies_v7`` (its "with" arm stands for it); the seeds whose probe chose
another horizon or changed its verdict (``gate.txt``) ran again at this code: ``suite/TASK/runs/``.
Seeds 10-19 of Kart-v0 and UR5Reach-v0 the same way (``gate_10_19.txt``, ``suite_10_19/``, ``v7_10_19/``).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "suite_bodies_v7"))
sys.argv = sys.argv[:1]
import io, contextlib  # noqa: E401,E402

with contextlib.redirect_stdout(io.StringIO()):  # v7's table module prints its own JSON on import
    import compare as v7  # noqa: E402

sc = v7.sc


def runs(task: str, *dirs: str) -> list[Path]:
    """Seeds 0-9: v7's "with" arm, replaced by the reruns in ``dirs`` (later ones win)."""
    got = dict(enumerate(v7.runs(task, "with")))  # seeds 0-9 in order
    for d in dirs:
        for p in sorted((HERE / d / task).glob("runs/shaped_s*/metrics.csv")):
            got[int(p.parent.name.split("_s")[-1])] = p
    return [got[s] for s in sorted(got)]


out = {}
for task in v7.TASKS:
    before = v7.summary(v7.runs(task, "with"), task)
    after = v7.summary(runs(task, "suite"), task)
    both = v7.summary(runs(task, "suite", "suite_base"), task)
    van = v7.summary(v7.runs(task, "vanilla"), task)
    cma = v7.summary(v7.runs(task, "cmaes"), task)
    rerun = sorted(int(p.parent.name.split("_s")[-1]) for p in (HERE / "suite" / task).glob("runs/shaped_s*/metrics.csv"))
    out[task] = {"fixed_4": before, "probed_4_8_16": after, "probed_and_4": both, "vanilla": van, "cmaes": cma,
                 "rerun_seeds": rerun, "fixed_over_vanilla": round(before["gens"] / van["gens"], 3),
                 "probed_over_vanilla": round(after["gens"] / van["gens"], 3),
                 "probed_and_4_over_vanilla": round(both["gens"] / van["gens"], 3)}
geo = lambda k: float(np.exp(np.mean([np.log(out[t][k]) for t in v7.TASKS])))  # noqa: E731
out["geomean_over_vanilla"] = {"fixed_4": round(geo("fixed_over_vanilla"), 3),
                               "probed_4_8_16": round(geo("probed_over_vanilla"), 3),
                               "probed_and_4": round(geo("probed_and_4_over_vanilla"), 3)}


def seeds_10_19(task: str) -> dict:
    """Seeds 10-19 and 0-19: the probed horizon's runs (``suite_10_19/`` where the probe changed the
    ninth session's choice, else that session's run, ``v7_10_19/``) against Vanilla-ES's and CMA-ES's
    (UR5Reach-v0: ``../suite_waypoints_v6/seeds_10_19``; Kart-v0: ``v7_10_19``), ratios of means with a
    95% bootstrap interval (seeds resampled in pairs)."""
    t, b = sc.THRESHOLDS[task], sc.BUDGET[task]
    base = HERE.parent / "suite_waypoints_v6" / "seeds_10_19" if task == "UR5Reach-v0" else HERE / "v7_10_19"
    def run(arm, s):
        p = HERE / "suite_10_19" / task / "runs" / f"shaped_s{s}" / "metrics.csv"
        if arm == "shaped_and_4" and (HERE / "suite_10_19_base" / task / "runs" / f"shaped_s{s}").is_dir():
            p = HERE / "suite_10_19_base" / task / "runs" / f"shaped_s{s}" / "metrics.csv"
        if arm.startswith("shaped") and not p.exists():
            p = HERE / "v7_10_19" / task / "runs" / f"shaped_s{s}" / "metrics.csv"
        elif not arm.startswith("shaped"):
            p = base / task / "runs" / f"{arm}_s{s}" / "metrics.csv"
        return sc.one(p, t, b) if p.exists() else None
    res = {}
    for arm in ("shaped", "shaped_and_4", "vanilla", "cmaes"):
        got = [run(arm, s) for s in range(10, 20)]
        if all(got):
            res[arm] = {"gens_per_seed": [x["gens"] for x in got], "late": round(float(np.mean([x["late"] for x in got])), 2)}
    for mine, first in (("shaped", "probed_4_8_16"), ("shaped_and_4", "probed_and_4")):
        rng = np.random.default_rng(0)
        a = np.array(out[task][first]["gens_per_seed"] + res[mine]["gens_per_seed"], float)
        for arm in ("vanilla", "cmaes"):
            if arm not in res:
                continue
            v = np.array(out[task][arm]["gens_per_seed"] + res[arm]["gens_per_seed"], float)
            boot = [a[i].mean() / v[i].mean() for i in (rng.integers(0, 20, 20) for _ in range(4000))]
            res[f"{mine}_0_19_over_{arm}"] = [round(a.mean() / v.mean(), 3),
                                              *np.percentile(boot, [2.5, 97.5]).round(2).tolist()]
        res[f"{mine}_0_19_gens"] = round(float(a.mean()), 2)
    return res


out["seeds_10_19"] = {task: seeds_10_19(task) for task in ("Kart-v0", "UR5Reach-v0")}
print(json.dumps(out, indent=1))
