"""``shoot_long_nearest``: where the probe can judge and chose the longest probed horizon (32), the nearest (16) runs
beside it. Each run it alters (``long_nearest/``, the arm ``comp``) against the same seed without it (``new``: 32
probed, the rest of this session's default) and with (8, 16) probed (``old``): generations to the threshold (censored
at the budget + 1) and late reward (the last 10 evaluations' mean).

    python docs/benchmarks/probe_horizon32_v20/long_nearest.py > docs/benchmarks/probe_horizon32_v20/long_nearest.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
V19 = HERE.parent / "shoot_unjudged_all_v19"
sys.path.insert(0, str(HERE.parent / "probe_chunk_v15"))
from compare import metrics, to_threshold  # noqa: E402  (probe_chunk_v15/compare.py)

L = HERE / "long_nearest"
# (body, seed, threshold, comp run, new run, old run)
RUNS = ([("Hover3D-v0", 4, 8.5, L / "hover3d_s4/runs/comp_s4", HERE / "hover3d_s4/runs/shaped_s4", HERE / "hover3d_s4/runs/old_s4"),
         ("Lander-v0", 0, 8.4, L / "lander_s0/runs/comp_s0", HERE / "lander_s0/runs/shaped_s0", HERE / "lander_s0/runs/old_s0")]
        + [("Bicycle-v0", s, 8.4, L / f"bicycle_s{s}/runs/comp_s{s}", HERE / f"bicycle_s{s}/runs/shaped_s{s}",
            HERE / f"bicycle_s{s}/runs/old_s{s}") for s in (1, 6, 9)]
        + [("CraneLoad-v0", s, 7.0, L / f"crane/runs/comp_s{s}", HERE / f"crane/bench/runs/shaped_s{s}",
            HERE / f"crane/bench_old/runs/old_s{s}") for s in (1, 2, 3)]
        + [("Hover-v0", s, 9.5, L / f"hover_s{s}/runs/comp_s{s}",
            (V19 / "hover/probe32/runs" / f"h32_s{s}") if s < 5 else HERE / f"hover59/runs/h32_s{s}",
            (V19 / "hover/bench/runs" / f"shaped_s{s}") if s < 5 else HERE / f"hover59/runs/shaped_s{s}") for s in (1, 3, 4, 7)]
        + [("MyDrone-v0", s, 8.0, L / f"mydrone_s{s}/runs/comp_s{s}", HERE / f"mydrone_s{s}/runs/shaped_s{s}",
            HERE / f"mydrone_s{s}/runs/old_s{s}") for s in (1, 2, 3, 5, 6, 8)]
        + [(t, s, thr, L / f"suite/{t}/runs/shaped_s{s}", HERE / f"suite/{t}/runs/shaped_s{s}",
            HERE / f"suite_default/{t}/runs/shaped_s{s}") for t, s, thr in
           (("CarNav-v0", 6, 200.0), ("SwimmerWay-v0", 1, 30.0), ("UR5Reach-v0", 6, 40.0))])


def late(m: dict) -> float:
    t = m["test_reward_mean"][np.isfinite(m["test_reward_mean"])]
    return float(np.mean(t[-10:]))


if __name__ == "__main__":
    rows = []
    for body, s, thr, *dirs in RUNS:
        ms = [metrics(d) for d in dirs]
        rows.append({"body": body, "seed": s, **{f"gens_{a}": to_threshold(m, thr) for a, m in zip(("comp", "new", "old"), ms)},
                     **{f"late_{a}": late(m) for a, m in zip(("comp", "new", "old"), ms)}})
    tot = {k: float(sum(r[k] for r in rows)) for k in rows[0] if k.startswith("gens_")}
    better = sum(r["gens_comp"] < r["gens_new"] for r in rows), sum(r["gens_comp"] > r["gens_new"] for r in rows)
    json.dump({"runs": rows, "generations_total": tot, "comp_faster_slower_than_new": better,
               "late_mean": {a: float(np.mean([r[f"late_{a}"] for r in rows])) for a in ("comp", "new", "old")}},
              sys.stdout, indent=1)
    print()
