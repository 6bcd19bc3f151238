"""Generations to each task's threshold per seed, and the label probe's choice per seed, for suite directories
(shaped-es suite run): python docs/benchmarks/gens.py DIR [DIR...] (the one script every suite study here uses;
``+c``: the query clipped, ``+k``: action-chunk targets). Thresholds and budgets as the waypoint suite's."""
import csv, glob, sys, os, json, numpy as np
TH = {"PointVel-v0": (8.5, 80), "PointForce-v0": (8.5, 80), "Unicycle-v0": (8.5, 50), "ReacherWay-v0": (-6.5, 80),
      "SwimmerWay-v0": (30, 30), "CarNav-v0": (200, 80), "UR5Reach-v0": (40, 60)}
def gens(run, task):
    th, B = TH[task]
    try: rows = list(csv.DictReader(open(run + "/metrics.csv")))
    except FileNotFoundError: return None
    for x in rows:
        if x["test_reward_mean"] and float(x["test_reward_mean"]) >= th: return int(x["generation"]) + 1
    return B + 1 if len(rows) >= B else None
def choice(run):
    try: d = json.load(open(run + "/label_probe.json")); return f"{d['frame']}{'+k' if d.get('targets') == 'chunk' else ''}{'' if d['query_clip'] is None else '+c'}"
    except Exception: return "-"
for d in sys.argv[1:]:
    print("==", d)
    for task in TH:
        runs = sorted(glob.glob(f"{d}/{task}/runs/shaped_s*"), key=lambda r: int(r.split("_s")[-1]))
        g = [gens(r, task) for r in runs]
        g2 = [x for x in g if x is not None]
        if not g2: continue
        B = TH[task][1]
        print(f"{task:15s} n={len(g2)} mean={np.mean(g2):5.1f} solved={sum(x <= B for x in g2)}  {g}  {[choice(r) for r in runs]}")
