"""A candidate accepted on a flat population (``shaping.mean_clone.accept_flat``): CarNav-v0 with sparse
waypoints (threshold 150, 80 generations) with and without it, and the two suite tasks whose populations can
be flat (CarNav-v0 dense, UR5Reach-v0) against ``../shoot_ahead_v10``'s runs (the same code without it).
Generations to the threshold (censored mean: an unsolved seed counts 81 / the budget + 1), seeds solved,
late test reward, and the generations in which every member returned the same. Prints JSON.

    python docs/benchmarks/accept_flat_v10/compare.py > docs/benchmarks/accept_flat_v10/compare.json
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
AHEAD = HERE.parent / "shoot_ahead_v10"
SUITE = {"CarNav-v0": (200.0, 80), "UR5Reach-v0": (40.0, 60)}


def one(path: Path, threshold: float, budget: int) -> dict:
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    t = [float(r["test_reward_mean"]) for r in rows]
    return {"gens": next((i + 1 for i, x in enumerate(t) if x >= threshold), budget + 1),
            "late": float(np.mean(t[-10:])),
            "flat": sum(r["train_reward_min"] == r["train_reward_max"] for r in rows),
            "accepted": sum(r.get("candidate_accepted") == "1" for r in rows)}


def arm(paths: list[Path], threshold: float, budget: int) -> dict | None:
    if not all(p.exists() for p in paths):
        return None
    per = [one(p, threshold, budget) for p in paths]
    g = [x["gens"] for x in per]
    return {"solved": sum(x <= budget for x in g), "gens": round(float(np.mean(g)), 1), "gens_per_seed": g,
            "late": round(float(np.mean([x["late"] for x in per])), 2),
            "flat_generations_per_run": round(float(np.mean([x["flat"] for x in per])), 1),
            "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1)}


out = {"CarNav-v0 sparse": {name: arm([HERE / "sparse" / name / "runs" / f"shaped_s{s}" / "metrics.csv"
                                        for s in range(10)], 150.0, 80)
                            for name in ("flat", "default", "ahead_0")}}
for task, (thr, budget) in SUITE.items():
    out[task] = {"flat": arm([HERE / "suite" / task / "runs" / f"shaped_s{s}" / "metrics.csv" for s in range(10)],
                             thr, budget),
                 "default": arm([AHEAD / "suite" / task / "runs" / f"shaped_s{s}" / "metrics.csv" for s in range(10)],
                                thr, budget)}
print(json.dumps(out, indent=1))
