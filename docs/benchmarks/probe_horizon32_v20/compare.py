"""The suite with 32 steps probed too: ``../shoot_unjudged_all_v19/compare.json`` (the previous default, seeds 0-9,
with Vanilla-ES and CMA-ES) with the runs a change alters replaced by their reruns, each beside the previous
default's rerun (``suite_default/TASK/runs``; it must reproduce v19's generations, checked). Two arms:
``new_default`` (``suite/``: 32 probed, where the probe cannot judge the rivals at the three shortest probed
horizons) and ``four_rivals`` (``suite_four/``: 32 probed, and where the probe cannot judge a fourth shooting rival,
commit 2dd35906's rule).
Generations to the threshold (censored at the budget + 1), paired-bootstrap ratios (``../probe_chunk_v15/compare.py``),
each changed run's late reward (its last 10 evaluations' mean) against the default's, and its wall time.

    python docs/benchmarks/probe_horizon32_v20/compare.py > docs/benchmarks/probe_horizon32_v20/compare.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "probe_chunk_v15"))
from compare import metrics, paired_ratio, to_threshold  # noqa: E402  (probe_chunk_v15/compare.py)

PREV = {k: v for k, v in json.loads((HERE.parent / "shoot_unjudged_all_v19" / "compare.json").read_text()).items()
        if isinstance(v, dict) and "threshold" in v}  # the tasks (not its geometric mean)


def late(m: dict) -> float:
    tests = m["test_reward_mean"][np.isfinite(m["test_reward_mean"])]  # (evaluations,)
    return float(np.mean(tests[-10:]))


def pair(name: str, s: int, thr: float, arm: str = "suite") -> dict | None:
    new_dir, old_dir = (HERE / d / name / "runs" / f"shaped_s{s}" for d in (arm, "suite_default"))
    if not new_dir.is_dir():
        return None
    m, old = metrics(new_dir), metrics(old_dir)
    return {"new": to_threshold(m, thr), "default": to_threshold(old, thr), "late_new": late(m),
            "late_default": late(old), "wall_new": float(m["wall_time_s"][-1]), "wall_default": float(old["wall_time_s"][-1])}


def task(name: str, seeds: list[int], arm: str = "suite") -> dict:
    p = PREV[name]
    thr = p["threshold"]
    prev = dict(zip(p["seeds"], p["new"]))
    new, changed, mismatch = dict(prev), {}, []
    for s in seeds:
        c = pair(name, s, thr, arm)
        if c is None:
            continue
        if c["default"] != prev[s]:
            mismatch.append(s)  # the default's rerun did not reproduce v19's run
        new[s], changed[s] = c["new"], c
    a = np.array([new[s] for s in p["seeds"]], float)
    b = np.array([prev[s] for s in p["seeds"]], float)
    return {"seeds": p["seeds"], "threshold": thr, "new": a.tolist(), "default": b.tolist(),
            "vanilla": p["vanilla"], "cmaes": p["cmaes"], "changed": changed, "default_not_reproduced": mismatch,
            "mean": {"new": float(a.mean()), "default": float(b.mean()), "vanilla": float(np.mean(p["vanilla"])),
                     "cmaes": float(np.mean(p["cmaes"]))},
            "late_shift": float(sum(c["late_new"] - c["late_default"] for c in changed.values()) / len(p["seeds"])),
            "wall_ratio_changed": (float(np.median([c["wall_new"] / c["wall_default"] for c in changed.values()]))
                                   if changed else None),
            "new_over_default": paired_ratio(a, b),
            "new_over_vanilla": paired_ratio(a, np.array(p["vanilla"], float)),
            "new_over_cmaes": paired_ratio(a, np.array(p["cmaes"], float))}


def reacher_10_19(arm: str = "suite") -> dict:
    """Seeds 10-19 (not in v19's compare.json): every seed's previous default rerun, and the arm's where it changed."""
    thr = PREV["ReacherWay-v0"]["threshold"]
    rows = []
    for s in range(10, 20):
        old = metrics(HERE / "suite_default" / "ReacherWay-v0" / "runs" / f"shaped_s{s}")
        same = {"new": to_threshold(old, thr), "default": to_threshold(old, thr), "late_new": late(old),
                "late_default": late(old)}
        rows.append(pair("ReacherWay-v0", s, thr, arm) or same)
    a, b = np.array([r["new"] for r in rows], float), np.array([r["default"] for r in rows], float)
    return {"seeds": list(range(10, 20)), "new": a.tolist(), "default": b.tolist(),
            "late_new": [r["late_new"] for r in rows], "late_default": [r["late_default"] for r in rows],
            "mean": {"new": float(a.mean()), "default": float(b.mean())}, "new_over_default": paired_ratio(a, b)}


def arm(name: str) -> dict:
    out = {t: task(t, list(range(10)), name) for t in PREV}
    out["ReacherWay-v0, seeds 10-19"] = reacher_10_19(name)
    for key, col in (("geometric_mean_over_vanilla", "new"), ("geometric_mean_over_vanilla_default", "default")):
        ratios = [paired_ratio(np.array(out[t][col], float), np.array(out[t]["vanilla"], float))[0] for t in PREV]
        out[key] = float(np.exp(np.mean(np.log(ratios))))  # as ../shoot_unjudged_all_v19/compare.py
    return out


if __name__ == "__main__":
    json.dump({"new_default": arm("suite"), "four_rivals": arm("suite_four")}, sys.stdout, indent=1)
    print()
