"""Which label source's candidate each run's accepted jumps came from (metrics.csv candidate_rival), per arm.
    python winners.py BENCH_DIR METHOD [--seeds A-B]"""
import collections
import csv
import sys

args = sys.argv[1:]
first, last = 0, 9
if "--seeds" in args:
    i = args.index("--seeds")
    first, last = (int(x) for x in args[i + 1].split("-"))
    del args[i:i + 2]
root, method = args
total = collections.Counter()
for s in range(first, last + 1):
    rows = list(csv.DictReader(open(f"{root}/runs/{method}_s{s}/metrics.csv")))
    won = collections.Counter(r["candidate_rival"] or "mphi" for r in rows if r["candidate_accepted"] in ("1", "True", "true"))
    total.update(won)
    print(f"seed {s}: " + ", ".join(f"{k} {v}" for k, v in sorted(won.items())))
print("all: " + ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
