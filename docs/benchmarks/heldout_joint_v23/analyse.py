"""Per-seed table of a benchmark folder from its runs' metrics.csv (works on pruned runs).
usage: python analyse.py BENCH_DIR [THRESHOLD]"""
import csv, json, os, sys
import numpy as np

b = sys.argv[1]
thr = float(sys.argv[2]) if len(sys.argv) > 2 else -72.0
per = {}
for run in sorted(os.listdir(f"{b}/runs")):
    m = list(csv.DictReader(open(f"{b}/runs/{run}/metrics.csv")))
    test = np.array([float(r["test_reward_mean"]) for r in m])
    hit = np.nonzero(test >= thr)[0]
    first = int(hit[0]) + 1 if hit.size else len(m) + 1  # generations done, censored at budget + 1
    wall = float(m[-1]["wall_time_s"])
    wall_thr = float(m[hit[0]]["wall_time_s"]) if hit.size else float("nan")
    line = f"{run:14s} first {first:3d}{'' if hit.size else '*'} late {test[-10:].mean():8.2f} final {test[-1]:8.2f} wall {wall:6.1f} wall_to_thr {wall_thr:6.1f} cpu {float(m[-1]['cpu_time_s']):6.1f}"
    acc = judged = None
    if "candidate_accepted" in m[0]:
        ok = lambda v: v not in ("", "nan")
        accr = [r for r in m if ok(r["candidate_accepted"]) and float(r["candidate_accepted"]) > 0]
        judged = sum(ok(r["candidate_gain"]) for r in m)
        kinds = [int(float(r["candidate_rival"])) for r in accr if ok(r["candidate_rival"])]
        probe = json.load(open(f"{b}/runs/{run}/label_probe.json"))
        ch = probe.get("choice") or probe.get("chosen") or {}
        line += f" acc {len(accr)}/{judged} kinds {kinds}"
        acc = len(accr)
    print(line)
    meth = run.rsplit("_s", 1)[0]
    per.setdefault(meth, []).append((first, test[-10:].mean(), wall, wall_thr, hit.size > 0, acc, judged, test))
print()
for meth, rs in per.items():
    f = np.array([r[0] for r in rs]); late = np.array([r[1] for r in rs]); w = np.array([r[2] for r in rs])
    wt = np.array([r[3] for r in rs])
    s = f"{meth:10s} n={len(rs)} solved {sum(r[4] for r in rs)}/{len(rs)} gens to thr mean {f.mean():.1f} median {np.median(f):.1f}  late mean {late.mean():.2f}  wall mean {w.mean():.1f}  wall to thr (solved) mean {(np.nanmean(wt) if np.isfinite(wt).any() else float('nan')):.1f}"
    if rs[0][5] is not None:
        s += f"  accepted/judged {sum(r[5] for r in rs)}/{sum(r[6] for r in rs)}"
    print(s)
