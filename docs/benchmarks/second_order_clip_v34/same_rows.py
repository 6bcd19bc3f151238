"""Whether two runs' metrics rows are equal in every column both have but timings. python same_rows.py RUN_A RUN_B"""
import csv, sys
skip = lambda k: "time" in k or k.endswith("_s") or "steps_per" in k or "rss" in k
a, b = (list(csv.DictReader(open(f"{d}/metrics.csv"))) for d in sys.argv[1:3])
diff = [(i, k) for i, (x, y) in enumerate(zip(a, b)) for k in x if k in y and not skip(k) and x[k] != y[k]]  # common columns
print(f"{sys.argv[1]} vs {sys.argv[2]}: {len(a)} vs {len(b)} rows; differing cells: {len(diff)} {diff[:5]}")
