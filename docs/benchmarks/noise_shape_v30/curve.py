"""Mean over seeds of a metrics.csv column in blocks of 5 generations, for several sets of runs.

    python curve.py GENERATIONS COLUMN name="glob" [name="glob" ...]
"""
import csv
import glob
import sys

import numpy as np

G, col = int(sys.argv[1]), sys.argv[2]
for arg in sys.argv[3:]:
    name, pattern = arg.split("=", 1)
    runs = []
    for f in sorted(glob.glob(pattern)):
        rows = list(csv.DictReader(open(f)))
        v = [float(r[col]) if r.get(col) not in (None, "", "nan") else np.nan for r in rows][:G]
        runs.append(v + [np.nan] * (G - len(v)))
    C = np.array(runs)  # (runs, G)
    with np.errstate(all="ignore"):
        print(f"{name:10s}({len(C)})", " ".join(f"{np.nanmean(C[:, i:i + 5]):6.1f}" for i in range(0, G, 5)))
