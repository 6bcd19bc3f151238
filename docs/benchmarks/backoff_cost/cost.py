"""What the back-off costs where the labels never pay: shaped vs Vanilla-ES over whole runs, per task.

Reads <task>/runs/<method>_s<seed>/metrics.csv next to this file (stdlib + NumPy only) and prints JSON.
Per task, method and seed: the run's generations, its wall time, CPU time and env steps (the last
row's ``wall_time_s``, ``cpu_time_s``: the process's CPU seconds, less sensitive to a shared machine's
load, and ``env_steps``), the generations asleep (``shaping_awake`` == 0; shaped only) and
candidates judged / accepted (``candidate_accepted``). Per task: medians over seeds, and the shaped /
vanilla ratios per paired seed (same seed) with their median, for wall time, CPU time and env steps.

    python docs/benchmarks/backoff_cost/cost.py [TASK_DIR ...]
"""

from __future__ import annotations

import csv
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

RUN = re.compile(r"^(?P<method>.+)_s(?P<seed>\d+)$")
HERE = Path(__file__).resolve().parent


def _f(x) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def run_cost(metrics: Path) -> dict:
    with metrics.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    last = rows[-1]
    out = {"generations": len(rows), "wall_time_s": _f(last["wall_time_s"]), "cpu_time_s": _f(last["cpu_time_s"]),
           "env_steps": int(_f(last["env_steps"])),
           "final_test_reward": _f(last["test_reward_mean"])}
    if "shaping_awake" in rows[0]:
        awake = [_f(r["shaping_awake"]) for r in rows]
        out["asleep_generations"] = sum(1 for a in awake if a == 0)
        out["asleep_share"] = out["asleep_generations"] / len(rows)
    if "candidate_accepted" in rows[0]:
        acc = [_f(r["candidate_accepted"]) for r in rows]
        acc = [a for a in acc if math.isfinite(a)]
        out["candidates_judged"], out["candidates_accepted"] = len(acc), int(sum(acc))
    return out


def task(d: Path, shaped: str = "shaped", vanilla: str = "vanilla") -> dict:
    per: dict[str, dict[int, dict]] = {}
    for r in sorted((d / "runs").iterdir()):
        m = RUN.match(r.name)
        if m and (r / "metrics.csv").is_file():
            per.setdefault(m["method"], {})[int(m["seed"])] = run_cost(r / "metrics.csv")
    out: dict = {"methods": {}}
    for method, seeds in per.items():
        s: dict = {"seeds": sorted(seeds), "per_seed": {str(k): v for k, v in sorted(seeds.items())}}
        for key in ("wall_time_s", "cpu_time_s", "env_steps", "generations", "asleep_share", "final_test_reward"):
            v = [seeds[k][key] for k in sorted(seeds) if key in seeds[k]]
            if v:
                s[f"{key}_median"] = float(np.median(v))
        if any("asleep_generations" in v for v in seeds.values()):
            asleep = sum(v.get("asleep_generations", 0) for v in seeds.values())
            gens = sum(v["generations"] for v in seeds.values())
            s["asleep_share_pooled"] = asleep / gens
            s["candidates_judged"] = sum(v.get("candidates_judged", 0) for v in seeds.values())
            s["candidates_accepted"] = sum(v.get("candidates_accepted", 0) for v in seeds.values())
        out["methods"][method] = s
    if shaped in per and vanilla in per:
        common = sorted(set(per[shaped]) & set(per[vanilla]))
        ratios: dict = {"paired_seeds": common}
        for key in ("wall_time_s", "cpu_time_s", "env_steps"):
            r = [per[shaped][k][key] / per[vanilla][k][key] for k in common]
            ratios[key] = {"paired_per_seed": {str(k): x for k, x in zip(common, r)},
                           "paired_median": float(np.median(r)) if r else math.nan,
                           "ratio_of_medians": out["methods"][shaped][f"{key}_median"]
                           / out["methods"][vanilla][f"{key}_median"]}
        ratios["same_final_test_reward_seeds"] = [
            k for k in common if per[shaped][k]["final_test_reward"] == per[vanilla][k]["final_test_reward"]]
        out[f"{shaped}_over_{vanilla}"] = ratios
    return out


def main() -> None:
    dirs = [Path(p) for p in sys.argv[1:]] or sorted(p for p in HERE.iterdir() if (p / "runs").is_dir())
    print(json.dumps({d.name: task(d) for d in dirs}, indent=2))


if __name__ == "__main__":
    main()
