"""Per task of a suite directory: generations to the threshold (censored means) of each method, the ratios
shaped / vanilla and shaped / cmaes with 95% bootstrap intervals (seeds resampled per method, 10,000
draws), and each method's late test reward (each run's mean test reward over its last 10 generations:
less noisy than one generation's) with a 95% bootstrap interval of the mean over seeds. Prints JSON.

    python docs/benchmarks/suite_waypoints_v6/stats.py SUITE_DIR [SUITE_DIR ...]   (stdlib + NumPy + PyYAML)
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
import yaml

THRESHOLDS = {"PointVel-v0": 8.5, "PointForce-v0": 8.5, "Unicycle-v0": 8.5, "ReacherWay-v0": -6.5,
              "SwimmerWay-v0": 30.0, "CarNav-v0": 200.0, "UR5Reach-v0": 40.0}


def run_stats(metrics: Path, threshold: float, budget: int) -> tuple[int, float]:
    with metrics.open(newline="") as fh:
        t = np.array([float(r["test_reward_mean"]) for r in csv.DictReader(fh)])  # (G,)
    hit = np.flatnonzero(t >= threshold)
    return (int(hit[0]) + 1 if hit.size else budget + 1), float(t[-10:].mean())  # generations run, 1-based


def boot_ratio(a: np.ndarray, b: np.ndarray, rng, n=10_000) -> list[float]:
    ra = rng.choice(a, size=(n, a.size)).mean(1) / rng.choice(b, size=(n, b.size)).mean(1)
    return [float(x) for x in np.percentile(ra, [2.5, 97.5])]


def boot_mean(a: np.ndarray, rng, n=10_000) -> list[float]:
    return [float(x) for x in np.percentile(rng.choice(a, size=(n, a.size)).mean(1), [2.5, 97.5])]


def task(tdir: Path, rng) -> dict:
    bench = yaml.safe_load((tdir / "benchmark.yaml").read_text())
    thr, budget = THRESHOLDS[tdir.name], int(bench["generations"])
    out: dict = {}
    for m in bench["methods"]:
        runs = sorted((tdir / "runs").glob(f"{m}_s*/metrics.csv"))
        if not runs:
            continue
        g, late = map(np.array, zip(*(run_stats(r, thr, budget) for r in runs)))
        out[m] = {"seeds": len(runs), "solved": int((g <= budget).sum()), "gens": float(g.mean()),
                  "late_reward": float(late.mean()), "late_reward_ci": boot_mean(late, rng), "_g": g}
    if "shaped" in out:
        for base in ("vanilla", "cmaes"):
            if base in out:
                out["shaped"][f"gens_over_{base}"] = out["shaped"]["gens"] / out[base]["gens"]
                out["shaped"][f"gens_over_{base}_ci"] = boot_ratio(out["shaped"]["_g"], out[base]["_g"], rng)
    for m in out.values():
        m.pop("_g")
    return out


if __name__ == "__main__":
    rng = np.random.default_rng(0)
    res = {}
    for d in sys.argv[1:]:
        res[d] = {t.name: task(t, rng) for t in sorted(Path(d).iterdir()) if (t / "benchmark.yaml").exists()}
    print(json.dumps(res, indent=1))
