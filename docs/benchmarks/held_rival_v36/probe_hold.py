"""Would the label probe tell a goal to hold from none? Its shooting candidate's returns with shoot_hold on against
off, on the same seeds (the probe's data and every other simulated candidate are the same in both), judged by the
probe's own test for simulated candidates (guides/probe_choice.clone_beats, the spread of the probe's returns as
the scale). One line per seed: H where the held-goal candidate beats the other, then the chosen horizons and the
two candidates' mean returns.
    python probe_hold.py HOLD_BENCH HOLD_METHOD REF_BENCH REF_METHOD [--seeds A-B]   (default 0-9)"""
import json
import sys

import numpy as np

from shaped_es.guides.probe_choice import clone_beats

args = sys.argv[1:]
seeds = range(10)
if "--seeds" in args:
    i = args.index("--seeds")
    a, b = (int(x) for x in args[i + 1].split("-"))
    seeds = range(a, b + 1)
    del args[i:i + 2]
hold_dir, hold_m, ref_dir, ref_m = args


def load(root, method, s):
    return json.load(open(f"{root}/runs/{method}_s{s}/label_probe.json"))


line, wins = [], 0
for s in seeds:
    h, o = load(hold_dir, hold_m, s), load(ref_dir, ref_m, s)
    seen = np.concatenate([np.ravel(o["zero_action"])] + [np.ravel(v) for v in o["returns"].values()]
                          + [np.ravel(v) for v in o["clones"].values()]
                          + [np.ravel(v) for v in (o.get("shoot_tried") or {}).values()])
    hs, os_ = np.array(h["shoot"] or [0.0]), np.array(o["shoot"] or [0.0])
    win = bool(h["shoot"] and o["shoot"] and len(hs) == len(os_) and clone_beats(hs, os_, float(np.ptp(seen)))[0])
    wins += win
    line.append(f"{'H' if win else '.'}{h['shoot_horizon']}/{o['shoot_horizon']}:{hs.mean():.1f}/{os_.mean():.1f}")
print(" ".join(line), f"| held goal beats the other on {wins} of {len(line)} seeds")
