"""Shaped / Vanilla-ES wall time of the swimmer's runs at generations 30 and 60, per seed and medians (stdlib only).

python docs/benchmarks/never_paying_swimmer_v25/table.py [RUNS_DIR]"""
import csv
import statistics
import sys
from pathlib import Path

runs = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent / "runs")
rows = {}
for s in range(10):
    R = list(csv.DictReader(open(runs / f"sw_shaped_s{s}" / "metrics.csv")))
    V = list(csv.DictReader(open(runs / f"sw_vanilla_s{s}" / "metrics.csv")))
    wall = lambda X, g: float(X[g]["wall_time_s"])  # noqa: E731 - seconds since the run's start, resumes included
    rows[s] = {"wall_30": wall(R, 29) / wall(V, 29), "wall_60": wall(R, 59) / wall(V, 59),
               "steps_30": float(R[29]["env_steps"]) / float(V[29]["env_steps"]),
               "steps_60": float(R[59]["env_steps"]) / float(V[59]["env_steps"]),
               "probe_s": wall(R, 0) - wall(V, 0), "awake": sum(int(r["shaping_awake"]) for r in R),
               "accepted": sum(int(r["candidate_accepted"] or 0) for r in R)}
print("| seed | wall 30 | wall 60 | env steps 30 | env steps 60 | probe + generation 0, s beyond Vanilla-ES's | awake generations of 60 | accepted |")
print("|---|---|---|---|---|---|---|---|")
for s, r in rows.items():
    print(f"| {s} | {r['wall_30']:.2f}x | {r['wall_60']:.2f}x | {r['steps_30']:.2f}x | {r['steps_60']:.2f}x | "
          f"{r['probe_s']:.1f} | {r['awake']} | {r['accepted']} |")
med = {k: statistics.median(r[k] for r in rows.values()) for k in ("wall_30", "wall_60", "steps_30", "steps_60")}
print(f"| median | {med['wall_30']:.2f}x | {med['wall_60']:.2f}x | {med['steps_30']:.2f}x | {med['steps_60']:.2f}x | | | |")
