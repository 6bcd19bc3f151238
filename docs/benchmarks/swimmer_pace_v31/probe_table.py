"""Per seed: the probe's choice, zero action's return, the best label-driven and best simulated-candidate returns,
and generation 0's population mean (metrics.csv train_reward_mean), from runs/shaped_s*/.
Usage: python probe_table.py [RUNS_DIR]"""
import csv
import json
import sys
from pathlib import Path

import numpy as np

root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).parent / "runs")
print("| seed | probe's choice | zero action | best label-driven | best simulated candidate | generation 0's population mean | accepted |")
print("|---|---|---|---|---|---|---|")
for run in sorted(root.glob("shaped_s*"), key=lambda p: int(p.name.split("_s")[1])):
    d = json.loads((run / "label_probe.json").read_text())
    rows = list(csv.DictReader((run / "metrics.csv").open()))
    lab = max(((k, np.mean(v)) for k, v in d["returns"].items()), key=lambda kv: kv[1])
    sims = {**d["clones"], **{f"shoot:{h}": v for h, v in (d.get("shoot_tried") or {}).items()}}
    sim = max(((k, np.mean(v)) for k, v in sims.items()), key=lambda kv: kv[1])
    choice = d["frame"] + ("" if d["query_clip"] is None else f"+clip{d['query_clip']:g}") + (
        f"+chunk{d['chunk']}" if d.get("chunk") else "")
    acc = sum(r["candidate_accepted"] == "1" for r in rows)
    print(f"| {run.name.split('_s')[1]} | {choice} | {np.mean(d['zero_action']):.1f} | {lab[0]} {lab[1]:.1f} | "
          f"{sim[0]} {sim[1]:.1f} | {float(rows[0]['train_reward_mean']):.1f} | {acc} |")
