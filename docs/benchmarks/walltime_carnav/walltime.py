"""Wall time (and generations, env steps) to a test reward of 200, shaped vs Vanilla-ES, per seed.

Reads runs/<method>_s<seed>/metrics.csv next to this file (stdlib + NumPy only) and prints JSON:

- per seed and method: ``wall_time_s``, ``cpu_time_s`` (the process's CPU seconds: less sensitive to a
  shared machine's load), ``generations`` (generation index + 1) and ``env_steps`` at the first
  row whose ``test_reward_mean`` >= the threshold; a run that never reaches it is **censored**: its last
  row's wall time, CPU time and env steps, and its generations + 1 (as ``summary.json`` does), ``reached`` false;
- per method: median (and mean) over seeds, seeds reached, censored count;
- ``ratio_of_medians``: shaped's median / vanilla's median;
- ``paired_ratio``: per seed shaped / vanilla (same seed), and their median.

    python docs/benchmarks/walltime_carnav/walltime.py [--threshold 200] [RUNS_DIR]
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import re
from pathlib import Path

import numpy as np

RUN = re.compile(r"^(?P<method>.+)_s(?P<seed>\d+)$")


def _f(x: str) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def to_threshold(metrics: Path, threshold: float) -> dict:
    with metrics.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise SystemExit(f"{metrics}: no rows")
    last = rows[-1]
    for r in rows:
        if _f(r["test_reward_mean"]) >= threshold:
            return {"reached": True, "wall_time_s": _f(r["wall_time_s"]), "cpu_time_s": _f(r["cpu_time_s"]),
                    "generations": int(r["generation"]) + 1, "env_steps": int(_f(r["env_steps"])),
                    "run_generations": len(rows), "run_wall_time_s": _f(last["wall_time_s"])}
    return {"reached": False, "wall_time_s": _f(last["wall_time_s"]), "cpu_time_s": _f(last["cpu_time_s"]),
            "generations": int(last["generation"]) + 2, "env_steps": int(_f(last["env_steps"])),
            "run_generations": len(rows), "run_wall_time_s": _f(last["wall_time_s"])}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("runs", nargs="?", default=str(Path(__file__).resolve().parent / "runs"))
    ap.add_argument("--threshold", type=float, default=200.0)
    ap.add_argument("--shaped", default="shaped")
    ap.add_argument("--vanilla", default="vanilla")
    a = ap.parse_args()

    per: dict[str, dict[int, dict]] = {}
    for d in sorted(Path(a.runs).iterdir()):
        m = RUN.match(d.name)
        if m and (d / "metrics.csv").is_file():
            per.setdefault(m["method"], {})[int(m["seed"])] = to_threshold(d / "metrics.csv", a.threshold)

    out: dict = {"threshold": a.threshold, "methods": {}}
    keys = ("wall_time_s", "cpu_time_s", "generations", "env_steps")
    for method, seeds in per.items():
        s = {"seeds": sorted(seeds), "reached": sum(v["reached"] for v in seeds.values()),
             "censored": [k for k, v in sorted(seeds.items()) if not v["reached"]],
             "per_seed": {str(k): v for k, v in sorted(seeds.items())}}
        for key in keys:
            v = np.array([seeds[k][key] for k in sorted(seeds)], dtype=np.float64)
            s[key] = {"median": float(np.median(v)), "mean": float(v.mean())}
        out["methods"][method] = s

    if a.shaped in per and a.vanilla in per:
        sh, va = per[a.shaped], per[a.vanilla]
        common = sorted(set(sh) & set(va))
        ratios: dict = {"paired_seeds": common}
        for key in keys:
            r = [sh[k][key] / va[k][key] for k in common]
            ratios[key] = {
                "ratio_of_medians": out["methods"][a.shaped][key]["median"]
                / out["methods"][a.vanilla][key]["median"],
                "paired_per_seed": {str(k): x for k, x in zip(common, r)},
                "paired_median": float(np.median(r)) if r else math.nan,
            }
        out[f"{a.shaped}_over_{a.vanilla}"] = ratios
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
