"""The label probe's candidate judged at generation 0 against the committed default without it
(``../test_policy_v11``, the same seeds and code otherwise): per task and seed, generations to the threshold
(censored at the budget + 1), the final test reward, and whether generation 0's candidate won. Where it lost,
the run must train exactly as the committed one (every row's ``train_reward_mean`` equal): a loss changes
nothing but the two extra rows' episodes (UR5Reach-v0's seed 8 is the exception: its committed run, made on
another machine, is not reproduced from generation 9 on by this machine even at its own commit, 478da71f,
nor with the candidate off). Per task, the ratios of the censored means, new shaped over the committed
shaped, Vanilla-ES and CMA-ES runs (the baselines' code is unchanged), with percentile-bootstrap intervals
(``report.aggregate.ratio_of_means``: each side's seeds resampled on their own).

    python docs/benchmarks/probe_candidate_v14/compare.py NEW_SUITE_DIR [NEW_SUITE_DIR ...] > compare.json
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np

from shaped_es.benchmark.summary import threshold_of
from shaped_es.report.aggregate import ratio_of_means

OLD = Path(__file__).resolve().parent.parent / "test_policy_v11"


def _rows(p: Path) -> list[dict]:
    with p.open(newline="") as fh:
        return list(csv.DictReader(fh))


def to_threshold(rows: list[dict], thr: float) -> int:
    """Generations done when the test reward first reached ``thr`` (budget + 1 if never)."""
    for r in rows:
        if r["test_reward_mean"] not in ("", None) and float(r["test_reward_mean"]) >= thr:
            return int(r["generation"]) + 1
    return len(rows) + 1


def paired_ratio(a: np.ndarray, b: np.ndarray, resamples: int = 10_000) -> dict:
    """mean(a) / mean(b) over the same seeds, with a 95% percentile-bootstrap interval that resamples seeds in
    pairs (the new and the committed run of a seed together: a run identical to its committed one adds no
    spread)."""
    rng = np.random.default_rng(0)
    idx = rng.integers(0, a.size, size=(resamples, a.size))  # (R, S) seeds drawn in pairs
    r = a[idx].mean(axis=1) / b[idx].mean(axis=1)  # (R,)
    return {"ratio": float(a.mean() / b.mean()), "ci": [float(np.quantile(r, 0.025)), float(np.quantile(r, 0.975))]}


def main() -> None:
    out: dict = {}
    for root in map(Path, sys.argv[1:]):
        for new_p in sorted(root.glob("*/runs/shaped_s*/metrics.csv")):
            task, run = new_p.parts[-4], new_p.parts[-2]
            old_ps = [p for p in OLD.glob(f"suite*/{task}/runs/{run}/metrics.csv")]
            if not old_ps:
                continue
            new, old = _rows(new_p), _rows(old_ps[0])
            thr = threshold_of(task, {})[0]
            won = new[0].get("candidate_accepted") in ("1", "1.0")
            same = [a["train_reward_mean"] for a in new] == [b["train_reward_mean"] for b in old]
            t = out.setdefault(task, {"threshold": thr, "seeds": {}})
            base = {m: to_threshold(_rows(old_ps[0].parent.parent / f"{m}_s{run.rsplit('_s', 1)[1]}" / "metrics.csv"),
                                    thr) for m in ("vanilla", "cmaes")}
            t["seeds"][run] = {**base, "gen0_won": won, "new": to_threshold(new, thr), "old": to_threshold(old, thr),
                               "final_new": float(new[-1]["test_reward_mean"]),
                               "final_old": float(old[-1]["test_reward_mean"]), "trains_as_old": same}
    for task, t in out.items():
        s = t["seeds"].values()
        n, o = np.array([v["new"] for v in s], float), np.array([v["old"] for v in s], float)
        t["mean_new"], t["mean_old"] = float(n.mean()), float(o.mean())
        t["gen0_won"] = int(sum(v["gen0_won"] for v in s))
        t["losers_train_as_old"] = all(v["trains_as_old"] for v in s if not v["gen0_won"])
        t["final_mean_new"] = float(np.mean([v["final_new"] for v in s]))
        t["final_mean_old"] = float(np.mean([v["final_old"] for v in s]))
        for other in ("old", "vanilla", "cmaes"):
            t[f"new_over_{other}"] = ratio_of_means(n, np.array([v[other] for v in s], float))
        t["new_over_old_paired"] = paired_ratio(n, o)
        for other in ("vanilla", "cmaes"):  # as test_policy_v11's table: seeds resampled in pairs
            t[f"new_over_{other}_paired"] = paired_ratio(n, np.array([v[other] for v in s], float))
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
