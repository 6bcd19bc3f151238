"""Where the extra goes: backoff_cost_v6's shaped runs against Vanilla-ES, per generation.

Adapted from ``../backoff_cost_v5/split.py``: the task directories are arguments (default: every
directory next to this file with a ``runs/``), there is no control arm, and the candidates are counted
per label variant (``candidate_rival`` of the winning row: 0 the run's own M_phi, 1 the frame rival,
2 the servo; ``rival_gain`` / ``servo_gain`` each variant's candidate's gain over the mean).

Reads <task>/runs/{shaped,vanilla}_s<seed>/metrics.csv (stdlib + NumPy) and prints JSON. Per task and
generation class -- gen0 (the label probe's steps are counted in it), awake_babble (awake, generation <
babble_generations = 20), awake_late, asleep -- the wall time per generation (differences of the
cumulative ``wall_time_s``) against Vanilla-ES's same seed and generation, env steps likewise, and the
mean phase times. Whole-run paired ratios to Vanilla-ES (wall, CPU, env steps), and a load-calibrated
wall ratio: the shaped run's wall over Vanilla-ES's times k, k = the median over the shaped run's asleep
generations (a Vanilla-ES generation's work) of shaped / vanilla wall per generation -- it takes out the
machine's speed difference between the two runs. Per seed: candidates judged / accepted (at which
generations, by which variant), the winning variant counts, gains > 0, final test rewards.

    python docs/benchmarks/backoff_cost_v6/split.py [TASK_DIR ...] > docs/benchmarks/backoff_cost_v6/split.json
"""

from __future__ import annotations

import csv
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
BABBLE_GENERATIONS = 20
VARIANTS = {"0": "own", "1": "frame", "2": "servo"}
RUN = re.compile(r"^shaped_s(?P<seed>\d+)$")


def _f(x) -> float:
    try:
        return float(x)
    except (TypeError, ValueError):
        return math.nan


def _rows(p: Path) -> list[dict]:
    with p.open(newline="") as fh:
        return list(csv.DictReader(fh))


def _per_gen(rows, key) -> np.ndarray:
    return np.diff([0.0] + [_f(r[key]) for r in rows])


def _cls(r) -> str:
    g = int(r["generation"])
    if g == 0:
        return "gen0"
    if r["shaping_awake"] != "1":
        return "asleep"
    return "awake_babble" if g < BABBLE_GENERATIONS else "awake_late"


def task(root: Path) -> dict:
    cats: dict = {}
    whole = {k: [] for k in ("wall_time_s", "cpu_time_s", "env_steps", "calibrated_wall", "asleep_speed_k")}
    seeds = {}
    for s in sorted(int(m["seed"]) for p in (root / "runs").iterdir() if (m := RUN.match(p.name))):
        sh = _rows(root / "runs" / f"shaped_s{s}" / "metrics.csv")
        va = _rows(root / "runs" / f"vanilla_s{s}" / "metrics.csv")
        dw, dv = _per_gen(sh, "wall_time_s"), _per_gen(va, "wall_time_s")
        ds, dvs = _per_gen(sh, "env_steps"), _per_gen(va, "env_steps")
        for i, r in enumerate(sh):
            c = cats.setdefault(_cls(r), {"generations": 0, "wall": 0.0, "vanilla_wall": 0.0, "steps": 0.0,
                                          "vanilla_steps": 0.0, "time_cloning_s": 0.0, "time_mphi_s": 0.0,
                                          "time_store_write_s": 0.0})
            c["generations"] += 1
            c["wall"] += dw[i]; c["vanilla_wall"] += dv[i]; c["steps"] += ds[i]; c["vanilla_steps"] += dvs[i]
            for k in ("time_cloning_s", "time_mphi_s", "time_store_write_s"):
                c[k] += float(np.nan_to_num(_f(r.get(k))))
        for k in ("wall_time_s", "cpu_time_s", "env_steps"):
            whole[k].append(_f(sh[-1][k]) / _f(va[-1][k]))
        asleep = np.array([r["shaping_awake"] == "0" for r in sh])
        kk = float(np.median(dw[asleep] / dv[asleep])) if asleep.any() else math.nan
        whole["asleep_speed_k"].append(kk)
        whole["calibrated_wall"].append(float(dw.sum() / (kk * dv.sum())))
        judged = [r for r in sh if r.get("candidate_accepted", "") != ""]
        acc = [r for r in judged if r["candidate_accepted"] == "1"]
        seeds[str(s)] = {
            "awake": int((~asleep).sum()), "asleep": int(asleep.sum()), "judged": len(judged),
            "accepted_generations": [int(r["generation"]) for r in acc],
            "accepted_by_variant": {v: sum(1 for r in acc if r.get("candidate_rival", "0") == k)
                                    for k, v in VARIANTS.items()},
            "better_by_variant": {v: sum(1 for r in judged if r.get("candidate_rival", "0") == k)
                                  for k, v in VARIANTS.items()},
            "rival_gain_positive": sum(1 for r in judged if _f(r.get("rival_gain")) > 0),
            "servo_gain_positive": sum(1 for r in judged if _f(r.get("servo_gain")) > 0),
            "final_test_reward": _f(sh[-1]["test_reward_mean"]), "vanilla_final_test_reward": _f(va[-1]["test_reward_mean"]),
            "same_final_as_vanilla": _f(sh[-1]["test_reward_mean"]) == _f(va[-1]["test_reward_mean"])}
    per_gen = {}
    for name, c in cats.items():
        n = c["generations"]
        per_gen[name] = {"generations": n, "wall_per_gen_s": c["wall"] / n, "vanilla_wall_per_gen_s": c["vanilla_wall"] / n,
                         "wall_ratio": c["wall"] / c["vanilla_wall"], "env_steps_ratio": c["steps"] / c["vanilla_steps"],
                         "extra_wall_s_all_seeds": c["wall"] - c["vanilla_wall"],
                         **{k + "_per_gen": c[k] / n for k in ("time_cloning_s", "time_mphi_s", "time_store_write_s")}}
    return {"per_generation_class": per_gen,
            "whole_run_over_vanilla": {k: {"paired_per_seed": v, "paired_median": float(np.median(v))} for k, v in whole.items()},
            "per_seed": seeds}


def main() -> None:
    dirs = [Path(p) for p in sys.argv[1:]] or sorted(p for p in HERE.iterdir() if (p / "runs").is_dir())
    print(json.dumps({d.name: task(d) for d in dirs}, indent=1))


if __name__ == "__main__":
    main()
