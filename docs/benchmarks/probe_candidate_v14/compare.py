"""The label probe's candidate judged at generation 0 against the committed default without it
(``../test_policy_v11``, the same seeds and code otherwise): per task and seed, generations to the threshold
(censored at the budget + 1), the final test reward, and whether generation 0's candidate won. Where it lost,
the run must train exactly as the committed one (every row's ``train_reward_mean`` equal): a loss changes
nothing but the two extra rows' episodes.

    python docs/benchmarks/probe_candidate_v14/compare.py NEW_SUITE_DIR [NEW_SUITE_DIR ...] > compare.json
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np

from shaped_es.benchmark.summary import threshold_of

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
            t["seeds"][run] = {"gen0_won": won, "new": to_threshold(new, thr), "old": to_threshold(old, thr),
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
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
