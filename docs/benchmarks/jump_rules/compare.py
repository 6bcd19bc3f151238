"""Per task: each jump-rule variant's shaped runs beside suite_waypoints_v6's (the default, Vanilla-ES,
CMA-ES): generations to the threshold (censored mean: an unsolved run counts budget + 1), seeds solved,
the late test reward (each run's mean over its last 10 generations; mean over seeds with a 95% bootstrap
interval), candidates accepted (in all, and from generation 30 on), jumps undone, awake generations.
Prints JSON.

    python docs/benchmarks/jump_rules/compare.py   (stdlib + NumPy + PyYAML)
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
V6 = HERE.parent / "suite_waypoints_v6"
sys.path.insert(0, str(V6))
from stats import THRESHOLDS  # noqa: E402

BUDGET = yaml.safe_load((V6 / "suite.yaml").read_text())["tasks"]
VARIANTS = {"z2": "accept_margin=2", "rev1": "revert_margin=1", "rev1u": "revert_margin=1",
            "rev2": "revert_margin=2"}


def one(path: Path, thr: float, budget: int) -> dict:
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["test_reward_mean"]) for r in rows])  # (G,)
    hit = np.flatnonzero(t >= thr)
    acc = [int(r["generation"]) for r in rows if r.get("candidate_accepted") == "1"]
    return {"gens": int(hit[0]) + 1 if hit.size else budget + 1, "late": float(t[-10:].mean()),
            "accepted": len(acc), "accepted_from_30": sum(g >= 30 for g in acc),
            "reverted": sum(r.get("jump_reverted") == "1" for r in rows),
            "awake": sum(r.get("shaping_awake") == "1" for r in rows)}


def arm(task_dir: Path, method: str, task: str, rng) -> dict | None:
    runs = sorted(task_dir.glob(f"runs/{method}_s*/metrics.csv"))
    if not runs:
        return None
    per = [one(p, THRESHOLDS[task], BUDGET[task]) for p in runs]
    g = np.array([p["gens"] for p in per])
    late = np.array([p["late"] for p in per])
    boot = rng.choice(late, size=(10_000, late.size)).mean(1)
    return {"seeds": len(per), "solved": int((g <= BUDGET[task]).sum()), "gens": float(g.mean()),
            "gens_per_seed": g.tolist(), "late_reward": float(late.mean()),
            "late_reward_ci": [float(x) for x in np.percentile(boot, [2.5, 97.5])],
            **{k: int(sum(p[k] for p in per)) for k in ("accepted", "accepted_from_30", "reverted")},
            "awake_mean": float(np.mean([p["awake"] for p in per]))}


def main() -> dict:
    rng = np.random.default_rng(0)
    out: dict = {}
    for task in BUDGET:
        res = {m: arm(V6 / task, m, task, rng) for m in ("shaped", "vanilla", "cmaes")}
        res = {("v6 default" if m == "shaped" else m): r for m, r in res.items() if r}
        for v, label in VARIANTS.items():
            if (r := arm(HERE / v / task, "shaped", task, rng)) is not None:
                res[f"{v} ({label})"] = r
            elif (HERE / v / task).is_dir():  # a study of this task whose runs are missing
                sys.exit(f"compare.py: {HERE / v / task} holds no runs/*/metrics.csv")
        out[task] = res
    return out


if __name__ == "__main__":
    print(json.dumps(main(), indent=1))
