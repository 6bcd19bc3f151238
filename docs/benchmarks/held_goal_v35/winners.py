"""Which label source's candidate each run's accepted jumps came from (metrics.csv candidate_rival: 0 the run's
M_phi, 1 the waypoint frame's, 2 the servo, 3 4 6 the shooting labels, 5 the label probe's candidate), per arm.
    python winners.py BENCH_DIR METHOD [--seeds A-B]   (default: every METHOD_sN run in BENCH_DIR/runs)"""
import collections
import csv
import sys
from pathlib import Path

args = sys.argv[1:]
seeds = None
if "--seeds" in args:
    i = args.index("--seeds")
    first, last = (int(x) for x in args[i + 1].split("-"))
    seeds = range(first, last + 1)
    del args[i:i + 2]
root, method = args
if seeds is None:
    seeds = sorted(int(p.name.rsplit("_s", 1)[1]) for p in Path(root, "runs").glob(f"{method}_s*"))
total = collections.Counter()
for s in seeds:
    rows = list(csv.DictReader(open(f"{root}/runs/{method}_s{s}/metrics.csv")))
    won = collections.Counter(r["candidate_rival"] for r in rows if r["candidate_accepted"] in ("1", "True", "true"))
    total.update(won)
    print(f"seed {s}: " + ", ".join(f"{k} {v}" for k, v in sorted(won.items())))
print("all: " + ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
