"""Held-out bodies with 32 steps probed too, seed by seed: generations to the threshold (censored at the budget + 1),
paired-bootstrap ratios (``../probe_chunk_v15/compare.py``), late reward (the last 10 evaluations' mean) and whole
runs' wall time. Arms: ``default`` (the previous default, probed horizons 4, 8, 16), ``new`` (the new default: 32
probed too, three rivals where the probe cannot judge, 16 beside a chosen 32: ``long_nearest/``'s reruns where that
alters a run), ``four`` (32 probed and a fourth rival where the probe
cannot judge: commit 2dd35906's rule, not kept), ``vanilla``. A seed's arms ran side by side in one benchmark,
except the quadrotor's seeds 0-4 default (``../shoot_unjudged_all_v19/quad``'s ``all`` arm, the same code) and the
hovercraft's seeds 0-4 (``../shoot_unjudged_all_v19/hover``: ``bench/`` and ``probe32/``, the same code).

    python docs/benchmarks/probe_horizon32_v20/heldout.py > docs/benchmarks/probe_horizon32_v20/heldout.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
V19 = HERE.parent / "shoot_unjudged_all_v19"
sys.path.insert(0, str(HERE.parent / "probe_chunk_v15"))
from compare import metrics, paired_ratio, to_threshold  # noqa: E402  (probe_chunk_v15/compare.py)

LN = HERE / "long_nearest"  # shoot_long_nearest's reruns of the runs it alters (the new default's there)


def new_run(comp: Path, before: Path) -> Path:
    """The new default's run: ``comp`` where shoot_long_nearest altered it (rerun), else ``before``."""
    return comp if comp.is_dir() else before


# body -> (threshold, {arm: [run dir per seed]})
BODIES = {
    "Hover-v0 (a new user's hovercraft)": (9.5, {
        "default": [V19 / "hover/bench/runs" / f"shaped_s{s}" for s in range(5)] + [HERE / "hover59/runs" / f"shaped_s{s}" for s in range(5, 10)],
        "new": [new_run(LN / f"hover_s{s}/runs/comp_s{s}", V19 / "hover/probe32/runs" / f"h32_s{s}") for s in range(5)]
        + [new_run(LN / f"hover_s{s}/runs/comp_s{s}", HERE / "hover59/runs" / f"h32_s{s}") for s in range(5, 10)],
        "vanilla": [V19 / "hover/bench/runs" / f"vanilla_s{s}" for s in range(5)] + [HERE / "hover59/runs" / f"vanilla_s{s}" for s in range(5, 10)]}),
    "Quad2D-v0 (a new user's quadrotor)": (9.0, {
        "default": [V19 / "quad/runs" / f"all_s{s}" for s in range(5)] + [HERE / "quad59/runs" / f"shaped_s{s}" for s in range(5, 10)],
        "four": [HERE / "quad/runs" / f"h32_s{s}" for s in range(5)] + [HERE / "quad59/runs" / f"h32_s{s}" for s in range(5, 10)]}),
    "CraneLoad-v0 (this session's new user's crane)": (7.0, {
        "default": [HERE / "crane/bench_old/runs" / f"old_s{s}" for s in range(5)],
        "new": [new_run(LN / "crane/runs" / f"comp_s{s}", HERE / "crane/bench/runs" / f"shaped_s{s}") for s in range(5)],
        "vanilla": [HERE / "crane/bench/runs" / f"vanilla_s{s}" for s in range(5)]}),
    "CheetahWaypoints-v0 (labels never pay), four rivals": (None, {
        arm: [HERE / "cheetah/runs" / f"{run}_s{s}" for s in range(5)]
        for arm, run in (("default", "shaped"), ("four", "h32"), ("vanilla", "vanilla"))}),
    "CheetahWaypoints-v0 (labels never pay), new default": (None, {
        arm: [HERE / "cheetah_new/runs" / f"{run}_s{s}" for s in range(5)]
        for arm, run in (("default", "old"), ("new", "shaped"), ("vanilla", "vanilla"))}),
}


# bodies whose probe decides differently with 32 probed on a few seeds only (the others' runs are the previous
# default's to the last digit: ``probe/new_vs_old.jsonl``): those seeds, both arms side by side (``shaped`` the new
# default, ``old`` the previous); body -> (threshold, {seed: benchmark dir})
CHANGED = {
    "MyDrone-v0": (8.0, {s: f"mydrone_s{s}" for s in (1, 2, 3, 5, 6, 8)}),
    "Hover3D-v0": (8.5, {s: f"hover3d_s{s}" for s in (4, 6)}),
    "Bicycle-v0": (8.4, {s: f"bicycle_s{s}" for s in (1, 6, 9)}),
    "Lander-v0": (8.4, {s: f"lander_s{s}" for s in (0, 5)}),
}


def changed(thr: float, runs: dict[int, str]) -> dict:
    out = {}
    for s, name in runs.items():
        d = HERE / name
        if not (d / "runs" / f"shaped_s{s}").is_dir():
            continue
        m = metrics(new_run(LN / name / "runs" / f"comp_s{s}", d / "runs" / f"shaped_s{s}"))
        old = metrics(d / "runs" / f"old_s{s}")
        out[s] = {"new": to_threshold(m, thr), "default": to_threshold(old, thr),
                  "late_new": float(np.mean(m["test_reward_mean"][np.isfinite(m["test_reward_mean"])][-10:])),
                  "late_default": float(np.mean(old["test_reward_mean"][np.isfinite(old["test_reward_mean"])][-10:]))}
    return out


PAIRS = (("new", "default"), ("four", "default"), ("new", "vanilla"), ("four", "vanilla"), ("default", "vanilla"))


def body(thr: float | None, arms: dict[str, list[Path]]) -> dict:
    ms = {a: [metrics(p) for p in runs if p.is_dir()] for a, runs in arms.items()}
    n = min(len(v) for v in ms.values())
    out = {"seeds": n}
    for a, v in ms.items():
        v = v[:n]
        late = [float(np.mean(m["test_reward_mean"][np.isfinite(m["test_reward_mean"])][-10:])) for m in v]
        out[a] = {"wall_s": [float(m["wall_time_s"][-1]) for m in v], "late": late, "late_mean": float(np.mean(late))}
        if thr is not None:
            g = [to_threshold(m, thr) for m in v]
            out[a].update(generations=g, mean=float(np.mean(g)),
                          solved=int(sum(x < len(m["wall_time_s"]) + 1 for x, m in zip(g, v))))
    for a, b in PAIRS:
        if a in arms and b in arms:
            key = f"{a}/{b}"
            w = np.array(out[a]["wall_s"]) / np.array(out[b]["wall_s"])
            out[key] = {"wall_median": float(np.median(w)), "wall_range": [float(w.min()), float(w.max())]}
            if thr is not None:
                out[key]["generations"] = paired_ratio(np.array(out[a]["generations"], float),
                                                       np.array(out[b]["generations"], float))
    return out


if __name__ == "__main__":
    out = {k: body(*v) for k, v in BODIES.items()}
    out["changed seeds"] = {k: changed(*v) for k, v in CHANGED.items()}
    json.dump(out, sys.stdout, indent=1)
    print()
