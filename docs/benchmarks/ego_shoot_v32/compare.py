"""Per-seed generations to a threshold, late test reward and the shooting frame each shaped run's probe chose, for
two run folders side by side (a study's runs against a reference's, seed for seed):

    python compare.py THRESHOLD BUDGET NEW_RUNS/shaped_s REF_RUNS/shaped_s [SEEDS]

Generations to the threshold: the first row (1-based) whose test_reward_mean reaches it, an unsolved seed counted as
BUDGET + 1 (censored); late reward: the mean of a run's last 10 test rewards; the ratio of the two mean generations
with a 95% percentile bootstrap over seeds (paired, 10,000 resamples, seed 0)."""
import csv
import json
import sys

import numpy as np


def read(run):
    rows = list(csv.DictReader(open(f"{run}/metrics.csv")))
    tests = [float(r["test_reward_mean"]) for r in rows if r.get("test_reward_mean")]
    return rows, tests


def gens(rows, th, budget):
    for r in rows:
        if r.get("test_reward_mean") and float(r["test_reward_mean"]) >= th:
            return int(r["generation"]) + 1
    return budget + 1


def frame(run):
    try:
        d = json.load(open(f"{run}/label_probe.json"))
    except OSError:
        return "-"
    return d.get("shoot_frame") or "world"


def accepted(rows):
    return sum(int(float(r.get("candidate_accepted") or 0)) for r in rows)


def main():
    th, budget, new, ref = float(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
    seeds = [int(s) for s in sys.argv[5].split(",")] if len(sys.argv) > 5 else list(range(10))
    g_new, g_ref, l_new, l_ref = [], [], [], []
    print("| seed | frame | generations (new / ref) | late reward (new / ref) | accepted (new / ref) | same rows |")
    print("|---|---|---|---|---|---|")
    for s in seeds:
        rn, tn = read(f"{new}{s}")
        rr, tr = read(f"{ref}{s}")
        same = [r["test_reward_mean"] for r in rn] == [r["test_reward_mean"] for r in rr]
        g_new.append(gens(rn, th, budget)), g_ref.append(gens(rr, th, budget))
        l_new.append(np.mean(tn[-10:])), l_ref.append(np.mean(tr[-10:]))
        print(f"| {s} | {frame(f'{new}{s}')} | {g_new[-1]} / {g_ref[-1]} | {l_new[-1]:.2f} / {l_ref[-1]:.2f} | "
              f"{accepted(rn)} / {accepted(rr)} | {'yes' if same else 'no'} |")
    g_new, g_ref, l_new, l_ref = map(np.array, (g_new, g_ref, l_new, l_ref))
    rng = np.random.default_rng(0)
    idx = rng.integers(0, len(seeds), size=(10_000, len(seeds)))
    ratio = g_new[idx].mean(1) / g_ref[idx].mean(1)
    diff = (l_new[idx] - l_ref[idx]).mean(1)
    print(f"\nnew {g_new.mean():.1f} ({(g_new <= budget).sum()} solved) against ref {g_ref.mean():.1f} "
          f"({(g_ref <= budget).sum()} solved): {g_new.mean() / g_ref.mean():.2f}x "
          f"[{np.percentile(ratio, 2.5):.2f}, {np.percentile(ratio, 97.5):.2f}]; late reward {l_new.mean():.2f} against "
          f"{l_ref.mean():.2f}, difference {l_new.mean() - l_ref.mean():+.2f} "
          f"[{np.percentile(diff, 2.5):+.2f}, {np.percentile(diff, 97.5):+.2f}]")


if __name__ == "__main__":
    main()
