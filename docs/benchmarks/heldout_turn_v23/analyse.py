"""Per-seed table of a benchmark folder from its runs' metrics.csv (works on pruned runs)."""
import csv, json, sys, os
import numpy as np

THR = -45.0
b = sys.argv[1]
rows = {}
for run in sorted(os.listdir(f"{b}/runs")):
    m = list(csv.DictReader(open(f"{b}/runs/{run}/metrics.csv")))
    test = np.array([float(r["test_reward_mean"]) for r in m])
    hit = np.nonzero(test >= THR)[0]
    first = int(hit[0]) + 1 if hit.size else len(m) + 1
    late = test[-10:].mean()
    wall = float(m[-1]["wall_time_s"])
    line = f"{run:12s} first {first:3d} late {late:8.2f} final {test[-1]:8.2f} wall {wall:6.1f}"
    if "candidate_accepted" in m[0]:
        acc = [r for r in m if r["candidate_accepted"] not in ("", "nan") and float(r["candidate_accepted"]) > 0]
        judged = [r for r in m if r["candidate_gain"] not in ("", "nan")]
        kinds = [int(float(r["candidate_rival"])) for r in acc if r["candidate_rival"] not in ("", "nan")]
        awake = sum(float(r["shaping_awake"]) > 0 for r in m if r["shaping_awake"] not in ("", "nan"))
        probe = json.load(open(f"{b}/runs/{run}/label_probe.json"))
        line += f" acc {len(acc)}/{len(judged)} kinds {kinds} awake {awake}"
    print(line)
