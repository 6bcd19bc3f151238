"""Whole runs, two code versions side by side: the new user's HalfCheetah with waypoints (labels never pay), shaped and
Vanilla-ES, 30 generations, inline, each seed's four runs in turn (old shaped, new shaped, old vanilla, new vanilla),
so the machine's noise falls on all four alike. Checks that both versions train the same policies (every metrics
column but the clocks) and prints JSON: per-seed wall times and the medians of the ratios.

    python docs/benchmarks/rollout_overhead_v21/cheetah_runs.py OLD_SRC NEW_SRC OUT_DIR [--seeds 5] [--generations 30]
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
from pathlib import Path

CLOCKS = {"wall_time_s", "cpu_time_s", "gen_time_s", "rollout_time_s", "time_mphi_s", "time_mphi_wait_s",
          "time_cloning_s", "clone_cpu_time_s", "time_store_write_s"}
HERE = Path(__file__).resolve().parent
CHEETAH = HERE.parent / "backoff_heavy_v13"  # cheetah_waypoints.py


def run(src: str, method: str, seed: int, gens: int, out: Path) -> list[dict]:
    if not (out / "metrics.csv").exists():
        env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, str(CHEETAH)])}
        subprocess.run([sys.executable, "-m", "shaped_es", "train", "--env", "cheetah_waypoints:CheetahWaypoints-v0",
                        "--method", method, "--generations", str(gens), "--seed", str(seed), "--executor", "inline",
                        "--out", str(out), "--quiet"], env=env, check=True, capture_output=True)
    with open(out / "metrics.csv") as fh:
        return list(csv.DictReader(fh))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("out")
    ap.add_argument("--seeds", type=int, default=5)
    ap.add_argument("--generations", type=int, default=30)
    a = ap.parse_args()
    out, res = Path(a.out), {"per_seed": []}
    for s in range(a.seeds):
        rows = {(v, m): run(src, m, s, a.generations, out / f"{v}_{m}_s{s}")
                for m in ("shaped", "vanilla") for v, src in (("old", a.old), ("new", a.new))}
        same = all([{k: x for k, x in r.items() if k not in CLOCKS} for r in rows[("old", m)]]
                   == [{k: x for k, x in r.items() if k not in CLOCKS} for r in rows[("new", m)]]
                   for m in ("shaped", "vanilla"))
        wall = {f"{v}_{m}": float(r[-1]["wall_time_s"]) for (v, m), r in rows.items()}
        res["per_seed"].append({"seed": s, "same_policies": same, "wall_time_s": wall,
                                "shaped_over_vanilla": {v: wall[f"{v}_shaped"] / wall[f"{v}_vanilla"] for v in ("old", "new")},
                                "new_over_old": {m: wall[f"new_{m}"] / wall[f"old_{m}"] for m in ("shaped", "vanilla")}})
        print(json.dumps(res["per_seed"][-1]), file=sys.stderr)
    ps = res["per_seed"]
    res["median"] = {"shaped_over_vanilla": {v: statistics.median(p["shaped_over_vanilla"][v] for p in ps) for v in ("old", "new")},
                     "new_over_old": {m: statistics.median(p["new_over_old"][m] for p in ps) for m in ("shaped", "vanilla")}}
    res["all_same_policies"] = all(p["same_policies"] for p in ps)
    print(json.dumps(res, indent=1))


if __name__ == "__main__":
    main()
