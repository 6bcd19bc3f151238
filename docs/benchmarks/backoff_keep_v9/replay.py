"""For runs made at keep_rate 0.2: which would run differently with keep_rate 0 (the old doubling), and
from which generation. Usage: python replay.py RUN/metrics.csv ... ; prints the task, seed, "diverge" and the first generation that would differ."""
import csv, sys
sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[3] / "src"))
from shaped_es.guides.label_budget import LabelBudget

def num(x):
    try: return float(x)
    except (TypeError, ValueError): return None

def replay(p, rate_run=0.2, rate_alt=0.0):
    rows = list(csv.DictReader(open(p)))
    run, alt = LabelBudget(5, 32, keep_rate=rate_run), LabelBudget(5, 32, keep_rate=rate_alt)
    for r in rows:
        a, b = run.begin(), alt.begin()
        if int(float(r["shaping_awake"])) != int(a):
            return ("MISMATCH", int(r["generation"]))
        if a != b:
            return ("diverge", int(r["generation"]))
        acc = num(r.get("candidate_accepted"))
        if acc is not None:
            for x in (run, alt):
                x.judge(bool(acc), num(r.get("candidate_gain")), num(r.get("train_reward_mean")),
                        num(r.get("jump_reverted")) == 1)
    return None

for p in sys.argv[1:]:
    v = replay(p)
    if v:
        parts = p.split("/")
        print(parts[-4], parts[-2].split("_s")[-1], v[0], v[1])
