"""Seeds solved and censored mean generations (a generation index g counts as g + 1, unsolved as the budget + 1,
as report.md counts) at thresholds around the registered ones, from the runs' metrics.csv."""
import csv
import numpy as np


def first(f, thr):
    for r in csv.DictReader(open(f)):
        if float(r["test_reward_mean"]) >= thr:
            return int(r["generation"]) + 1
    return None


for env, benches, thrs, G in [
        ("GridPoint-v0", [("bench_grid", "shaped"), ("bench_grid", "vanilla"), ("bench_grid_oracle", "oracle")],
         [9.0, 10.0, 11.0], 150),
        ("ThrustCar-v0", [("bench_car", "shaped"), ("bench_car", "vanilla"), ("bench_car_oracle", "oracle")],
         [5.0, 5.5, 5.84, 6.0], 100)]:
    for thr in thrs:
        out = []
        for b, m in benches:
            g = [first(f"{b}/runs/{m}_s{s}/metrics.csv", thr) for s in range(10)]
            cm = np.mean([x if x is not None else G + 1 for x in g])
            out.append(f"{m} {sum(x is not None for x in g)}/10 in {cm:.1f}")
        print(f"| {env} | {thr} | " + " | ".join(out) + " |")
