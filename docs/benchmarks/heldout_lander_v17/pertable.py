"""Per-seed table from each run's metrics.csv (and label_probe.json), truncated at budget B (first B rows)."""
import csv, json, sys, os, numpy as np
thr = 8.4
def iqm(x):
    x = np.sort(np.asarray(x)); n = len(x); lo = int(np.floor(n * 0.25)); return x[lo:n - lo].mean()
def boot(x, f=iqm, n=2000, seed=0):
    r = np.random.default_rng(seed); x = np.asarray(x)
    return np.percentile([f(r.choice(x, len(x))) for _ in range(n)], [2.5, 97.5])
def table(benchdir, method, B, seeds):
    rows = []
    for s in seeds:
        d = f"{benchdir}/runs/{method}_s{s}"
        m = list(csv.DictReader(open(f"{d}/metrics.csv")))[:B]
        gen = next((int(r["generation"]) + 1 for r in m if float(r["test_reward_mean"]) >= thr), None)
        row = dict(seed=s, gens=gen, final=float(m[-1]["test_reward_mean"]), wall=float(m[-1]["wall_time_s"]),
                   cpu=float(m[-1]["cpu_time_s"]))
        if "candidate_accepted" in m[0]:
            acc = [r["candidate_accepted"] for r in m]
            row["acc"] = sum(1 for a in acc if a not in ("", "nan") and float(a) > 0)
            row["judged"] = sum(1 for a in acc if a not in ("", "nan"))
            row["asleep"] = sum(1 for r in m if r["shaping_awake"] in ("0", "0.0"))
            row["gen0"] = "won" if m[0]["candidate_accepted"] in ("1", "1.0") else ("lost" if m[0]["candidate_accepted"] not in ("", "nan") else "–")
            p = f"{d}/label_probe.json"
            if os.path.exists(p):
                j = json.load(open(p)); row["probe"] = f"{j['frame']}/{j['query_clip']}; shoot {'kept' if j.get('shoot_on') else 'dropped'} h={j.get('shoot_horizon')}"
            else:
                row["probe"] = "no probe (controller labels)"
        rows.append(row)
    return rows
def fmt(rows, B, title):
    out = [f"**{title}** (budget {B} generations)", ""]
    shaped = "acc" in rows[0]
    hdr = "| seed | gens to 8.4 | final test | wall_time_s | cpu_time_s |" + (" accepted/judged | gens asleep | gen-0 probe candidate | probe choice |" if shaped else "")
    out += [hdr, "|" + "---|" * hdr.count("|")[:-1] if False else "|" + "---|" * (hdr.count("|") - 1)]
    for r in rows:
        line = f"| {r['seed']} | {r['gens'] or '—'} | {r['final']:.2f} | {r['wall']:.1f} | {r['cpu']:.1f} |"
        if shaped: line += f" {r['acc']}/{r['judged']} | {r['asleep']} | {r['gen0']} | {r['probe']} |"
        out.append(line)
    g = [r['gens'] or B + 1 for r in rows]; f = [r['final'] for r in rows]; lo, hi = boot(f)
    solved = [r['gens'] for r in rows if r['gens']]
    out += ["", f"solved {len(solved)}/{len(rows)}; generations to 8.4 censored mean {np.mean(g):.1f}, median {np.median(g):.1f}"
            f" (solved seeds only: median {np.median(solved) if solved else float('nan'):.0f}); final test reward IQM {iqm(f):.2f} [{lo:.2f}, {hi:.2f}];"
            f" mean wall_time_s {np.mean([r['wall'] for r in rows]):.1f}, cpu_time_s {np.mean([r['cpu'] for r in rows]):.1f}"
            + (f"; accepted {sum(r['acc'] for r in rows)}/{sum(r['judged'] for r in rows)} judged; gen-0 probe candidate won {sum(r['gen0']=='won' for r in rows)}/{len(rows)}" if shaped else ""), ""]
    return "\n".join(out)
if __name__ == "__main__":
    benchdir, method, B, first = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
    print(fmt(table(benchdir, method, B, range(first, first + 10)), B, f"{method}, seeds {first}-{first+9} ({benchdir})"))
