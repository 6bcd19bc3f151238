"""Per-seed table from the benchmarks' metrics.csv files (generations done to the threshold, late reward, wall time)."""
import csv, json, sys, os
T = 97.6
def load(run):
    rows = list(csv.DictReader(open(os.path.join(run, "metrics.csv"))))
    first = next((int(r["generation"]) + 1 for r in rows if r["test_reward_mean"] and float(r["test_reward_mean"]) >= T), None)
    tests = [float(r["test_reward_mean"]) for r in rows if r["test_reward_mean"]]
    late = sum(tests[-10:]) / len(tests[-10:])
    acc = sum(int(float(r["candidate_accepted"])) for r in rows if r.get("candidate_accepted"))
    jud = sum(1 for r in rows if r.get("candidate_accepted") not in (None, ""))
    wall_to = next((float(r["wall_time_s"]) for r in rows if r["test_reward_mean"] and float(r["test_reward_mean"]) >= T), None)
    return dict(first=first, late=late, wall=float(rows[-1]["wall_time_s"]), wall_to=wall_to, acc=acc, jud=jud, n=len(rows))
for bench in sys.argv[1:]:
    print("##", bench)
    runs = sorted(os.listdir(os.path.join(bench, "runs")))
    for r in runs:
        d = load(os.path.join(bench, "runs", r))
        print(f"{r:12s} first={d['first']} late={d['late']:.2f} wall={d['wall']:.1f} wall_to={d['wall_to']} acc/jud={d['acc']}/{d['jud']} rows={d['n']}")
