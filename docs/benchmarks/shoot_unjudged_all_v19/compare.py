"""The suite at this session's default: ``../shoot_unjudged_v18/compare.json`` (the previous default, seeds 0-9,
with Vanilla-ES and CMA-ES) with the runs the new rule changes replaced by their reruns (``suite/TASK/runs``:
the shooting rival at every probed horizon where the probe cannot judge, and CarNav-v0's seed 1, whose probe a
passed-over variant no longer judges). Generations to the threshold (censored at the budget + 1), paired-bootstrap
ratios (``../probe_chunk_v15/compare.py``), and each changed run's late reward (its last 10 evaluations' mean)
against the previous run's.

    python docs/benchmarks/shoot_unjudged_all_v19/compare.py > docs/benchmarks/shoot_unjudged_all_v19/compare.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "probe_chunk_v15"))
from compare import metrics, paired_ratio, to_threshold  # noqa: E402  (probe_chunk_v15/compare.py)

PREV = {k: v for k, v in json.loads((HERE.parent / "shoot_unjudged_v18" / "compare.json").read_text()).items()
        if "threshold" in v}  # the tasks (not its geometric mean)
PREV_RUNS = {t: HERE.parent / "shoot_unjudged_v18" / "suite" / t / "runs" for t in PREV}
PREV_RUNS_CARNAV_S1 = HERE.parent / "probe_clip_long_v16" / "suite" / "CarNav-v0" / "runs"


def late(m: dict) -> float:
    tests = m["test_reward_mean"][np.isfinite(m["test_reward_mean"])]  # (evaluations,)
    return float(np.mean(tests[-10:]))


def task(name: str, seeds: list[int]) -> dict:
    p = PREV[name]
    thr = p["threshold"]
    prev = dict(zip(p["seeds"], p["new"]))
    new, changed = dict(prev), {}
    for s in seeds:
        run = HERE / "suite" / name / "runs" / f"shaped_s{s}"
        if not run.is_dir():
            continue
        m = metrics(run)
        old_dir = PREV_RUNS_CARNAV_S1 if (name, s) == ("CarNav-v0", 1) else PREV_RUNS[name]
        old = metrics(old_dir / f"shaped_s{s}")
        new[s] = to_threshold(m, thr)
        changed[s] = {"new": new[s], "previous": to_threshold(old, thr), "late_new": late(m), "late_previous": late(old)}
    a = np.array([new[s] for s in p["seeds"]], float)
    b = np.array([prev[s] for s in p["seeds"]], float)
    out = {"seeds": p["seeds"], "threshold": thr, "new": a.tolist(), "previous": b.tolist(),
           "vanilla": p["vanilla"], "cmaes": p["cmaes"], "changed": changed,
           "mean": {"new": float(a.mean()), "previous": float(b.mean()), "vanilla": float(np.mean(p["vanilla"])),
                    "cmaes": float(np.mean(p["cmaes"]))},
           "late_shift": float(sum(c["late_new"] - c["late_previous"] for c in changed.values()) / len(p["seeds"])),
           "new_over_previous": paired_ratio(a, b),
           "new_over_vanilla": paired_ratio(a, np.array(p["vanilla"], float)),
           "new_over_cmaes": paired_ratio(a, np.array(p["cmaes"], float))}
    return out


def reacher_10_19() -> dict:
    thr = PREV["ReacherWay-v0"]["threshold"]
    rows = []
    for s in range(10, 20):
        m, old = metrics(HERE / "suite" / "ReacherWay-v0" / "runs" / f"shaped_s{s}"), metrics(PREV_RUNS["ReacherWay-v0"] / f"shaped_s{s}")
        rows.append((to_threshold(m, thr), to_threshold(old, thr), late(m), late(old)))
    a, b = np.array([r[0] for r in rows], float), np.array([r[1] for r in rows], float)
    return {"seeds": list(range(10, 20)), "new": a.tolist(), "previous": b.tolist(),
            "late_new": [r[2] for r in rows], "late_previous": [r[3] for r in rows],
            "mean": {"new": float(a.mean()), "previous": float(b.mean())}, "new_over_previous": paired_ratio(a, b)}


if __name__ == "__main__":
    out = {t: task(t, list(range(10))) for t in PREV}
    out["ReacherWay-v0, seeds 10-19"] = reacher_10_19()
    ratios = [out[t]["new_over_vanilla"][0] for t in PREV]
    out["geometric_mean_over_vanilla"] = float(np.exp(np.mean(np.log(ratios))))
    json.dump(out, sys.stdout, indent=1)
    print()
