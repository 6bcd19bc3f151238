"""Per-seed table of the push benchmark from bench/runs/*/metrics.csv (run: python3 table.py [bench|bench80])."""
import csv, json, statistics as st, sys
B = sys.argv[1] if len(sys.argv) > 1 else "bench"
T = 9.0
rows = {}
for m in ["shaped", "vanilla"]:
    for s in range(10):
        r = list(csv.DictReader(open(f"{B}/runs/{m}_s{s}/metrics.csv")))
        test = [float(x["test_reward_mean"]) for x in r if x["test_reward_mean"]]
        hit = next((i + 1 for i, v in enumerate(test) if v >= T), None)
        acc = sum(1 for x in r if x.get("candidate_accepted") in ("1", "1.0", "True"))
        judged = sum(1 for x in r if x.get("candidate_accepted") not in (None, ""))
        awake = sum(1 for x in r if x.get("shaping_awake") in ("1", "1.0"))
        rows[m, s] = dict(gens=hit or len(r) + 1, solved=hit is not None, late=st.mean(test[-10:]), final=test[-1],
                          best=max(test), wall=float(r[-1]["wall_time_s"]), cpu=float(r[-1]["cpu_time_s"]),
                          steps=int(float(r[-1]["env_steps"])), acc=acc, judged=judged, awake=awake)
print("seed | shaped final / late / wall s / cpu s / acc/judged / awake | vanilla final / late / wall s / cpu s | wall ratio | cpu ratio")
for s in range(10):
    a, b = rows["shaped", s], rows["vanilla", s]
    print(f"{s} | {a['final']:.2f} / {a['late']:.2f} / {a['wall']:.1f} / {a['cpu']:.1f} / {a['acc']}/{a['judged']} / {a['awake']} | "
          f"{b['final']:.2f} / {b['late']:.2f} / {b['wall']:.1f} / {b['cpu']:.1f} | {a['wall']/b['wall']:.2f} | {a['cpu']/b['cpu']:.2f}")
for m in ["shaped", "vanilla"]:
    v = [rows[m, s] for s in range(10)]
    print(m, "gens(censored) %.1f solved %d/10 late mean %.2f final mean %.2f wall mean %.1f cpu mean %.1f steps %.0f acc %d/%d" % (
        st.mean(x["gens"] for x in v), sum(x["solved"] for x in v), st.mean(x["late"] for x in v),
        st.mean(x["final"] for x in v), st.mean(x["wall"] for x in v), st.mean(x["cpu"] for x in v),
        st.mean(x["steps"] for x in v), sum(x["acc"] for x in v), sum(x["judged"] for x in v)))
none = [s for s in range(10) if rows["shaped", s]["acc"] == 0]
print("seeds with no accepted candidate:", none)
for key in ["wall", "cpu"]:
    rs = [rows["shaped", s][key] / rows["vanilla", s][key] for s in none]
    print(f"  {key} ratio on them: median {st.median(rs):.2f}, mean {st.mean(rs):.2f}, sum-ratio {sum(rows['shaped', s][key] for s in none)/sum(rows['vanilla', s][key] for s in none):.2f}")
