"""The ninth session's table: per task, the default before the shooting rival, the default with it (the
label probe keeps it per seed), Vanilla-ES and CMA-ES, 10 seeds (0-9): generations to the threshold
(censored mean), seeds solved, late test reward, candidates accepted and those that were the shooting
labels'. Prints JSON.

    python docs/benchmarks/suite_bodies_v7/compare.py

Where each arm's runs are:
- the seven v6 tasks without the rival, Vanilla-ES and CMA-ES: ``../suite_waypoints_v6``;
- Rover-v0 and Kart-v0 without the rival: ``noshoot/``; their baselines: ``baselines/``;
- with the rival: ``shoot/`` (PointVel, PointForce, Unicycle, Rover, Kart: every seed; the probe kept the
  rival on all 50) and ``shoot_gated/TASK_sK`` (the UR5Reach-v0, CarNav-v0 and SwimmerWay-v0 seeds whose
  probe kept it); a seed whose probe dropped it (every Reacher seed, 4 UR5, 9 CarNav, 9 swimmer seeds)
  runs the default's code path, so its v6 run stands for it (``gate.txt``: the probe's verdicts).
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
import suite_compare as sc  # noqa: E402

V6 = HERE.parent / "suite_waypoints_v6"
NEW = {"Rover-v0": (8.0, 80), "Kart-v0": (8.0, 120)}  # threshold, budget
sc.THRESHOLDS.update({k: v[0] for k, v in NEW.items()})
sc.BUDGET.update({k: v[1] for k, v in NEW.items()})
TASKS = ["PointVel-v0", "PointForce-v0", "Unicycle-v0", "Rover-v0", "Kart-v0", "ReacherWay-v0", "SwimmerWay-v0",
         "CarNav-v0", "UR5Reach-v0"]


def runs(task: str, arm: str) -> list[Path]:
    """metrics.csv paths of one arm of one task, seeds 0-9 in order."""
    def pick(d, method="shaped"):
        return {int(p.parent.name.split("_s")[-1]): p for p in sorted((d / task).glob(f"runs/{method}_s*/metrics.csv"))}
    if arm in ("vanilla", "cmaes"):
        got = pick(HERE / "baselines" if task in NEW else V6, arm)
    elif arm == "without":
        got = pick(HERE / "noshoot" if task in NEW else V6)
    else:  # with the shooting rival: its own runs where it ran, else the default's
        got = {} if task in NEW else pick(V6)
        got |= pick(HERE / "shoot")
        for d in sorted((HERE / "shoot_gated").glob(f"{task}_s*")):
            got |= pick(d)
    return [got[s] for s in sorted(got)]


def summary(paths: list[Path], task: str) -> dict:
    per = [sc.one(p, sc.THRESHOLDS[task], sc.BUDGET[task]) for p in paths]
    shoot = 0
    for p in paths:
        with p.open(newline="") as fh:
            shoot += sum(r.get("candidate_accepted") == "1" and r.get("candidate_rival") == "3" for r in csv.DictReader(fh))
    g = np.array([x["gens"] for x in per])
    return {"seeds": len(per), "solved": int((g <= sc.BUDGET[task]).sum()), "gens": round(float(g.mean()), 1),
            "gens_per_seed": g.tolist(), "late_reward": round(float(np.mean([x["late"] for x in per])), 2),
            "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1),
            "accepted_shoot": shoot}


out = {}
for task in TASKS:
    out[task] = {arm: summary(runs(task, arm), task) for arm in ("without", "with", "vanilla", "cmaes")}
    v = out[task]["vanilla"]["gens"]
    out[task]["with_over_vanilla"] = round(out[task]["with"]["gens"] / v, 3)
    out[task]["without_over_vanilla"] = round(out[task]["without"]["gens"] / v, 3)
geo = lambda k: float(np.exp(np.mean([np.log(out[t][k]) for t in TASKS])))  # noqa: E731
out["geomean_over_vanilla"] = {"with": round(geo("with_over_vanilla"), 3), "without": round(geo("without_over_vanilla"), 3)}
print(json.dumps(out, indent=1))
