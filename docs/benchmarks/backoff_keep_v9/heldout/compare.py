"""Bodies the method was not developed on (``../../shoot_horizon_v8/heldout``: the tractor, the hover, two
new users' drone and boat), run again at the final default (``keep``: all 10 seeds, 40 generations) and,
where the back-off's schedule would differ, with the old doubling (``double``: ``backoff_keep_rate=0``);
Vanilla-ES and CMA-ES from the tenth session's runs. Per arm: generations to the threshold (censored mean:
an unsolved seed counts 41), seeds solved, final test reward, accepted candidates per run; the ratio of
means to Vanilla-ES's with a 95% bootstrap interval (seeds resampled in pairs). Prints JSON.

    python docs/benchmarks/backoff_keep_v9/heldout/compare.py
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OLD = HERE.parent.parent / "shoot_horizon_v8" / "heldout" / "runs"
BODIES = {"Tractor-v0": -6.0, "Hover3D-v0": 8.5, "MyDrone-v0": 8.0, "MyBoat-v0": 8.5}
BUDGET = 40


def one(path: Path, threshold: float) -> dict:
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    test = [float(r["test_reward_mean"]) for r in rows]
    hit = next((i + 1 for i, x in enumerate(test) if x >= threshold), BUDGET + 1)
    return {"gens": hit, "final": test[-1], "accepted": sum(r.get("candidate_accepted") == "1" for r in rows),
            "wall": float(rows[-1]["wall_time_s"])}


def path(body: str, arm: str, seed: int) -> Path:
    if arm in ("vanilla", "cmaes"):
        return OLD / body / arm / f"{arm}_s{seed}" / "metrics.csv"
    p = HERE / "runs" / body / "double" / f"shaped_s{seed}" / "metrics.csv"
    return p if arm == "double" and p.exists() else HERE / "runs" / body / "keep" / f"shaped_s{seed}" / "metrics.csv"


out, rng = {}, np.random.default_rng(0)
for body, thr in BODIES.items():
    out[body] = {}
    for arm in ("keep", "double", "vanilla", "cmaes"):
        paths = [path(body, arm, s) for s in range(10)]
        if not all(p.exists() for p in paths):
            continue
        per = [one(p, thr) for p in paths]
        g = np.array([x["gens"] for x in per], float)  # (10,)
        out[body][arm] = {"solved": int((g <= BUDGET).sum()), "gens": round(float(g.mean()), 1),
                          "gens_per_seed": g.astype(int).tolist(),
                          "final": round(float(np.mean([x["final"] for x in per])), 2),
                          "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1)}
    out[body]["double_seeds"] = sorted(int(p.parent.name.split("_s")[-1])
                                       for p in (HERE / "runs" / body / "double").glob("shaped_s*/metrics.csv"))
    van = out[body].get("vanilla")
    for arm in ("keep", "double"):
        if van and arm in out[body]:
            x, y = np.array(out[body][arm]["gens_per_seed"], float), np.array(van["gens_per_seed"], float)
            boot = [x[i].mean() / y[i].mean() for i in (rng.integers(0, 10, 10) for _ in range(4000))]
            out[body][f"{arm}_over_vanilla"] = [round(x.mean() / y.mean(), 3),
                                                *np.percentile(boot, [2.5, 97.5]).round(2).tolist()]
print(json.dumps(out, indent=1))
