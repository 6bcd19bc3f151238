"""Which committed runs would the heavy-loss rule change? Replays each shaped run's judgements.

A run's back-off schedule depends only on its judged generations (accepted or not, the candidate's gain, the
population's returns), so feeding a committed run's metrics rows to :class:`LabelBudget` reproduces its
``shaping_awake`` column exactly (checked for every run), and feeding them with ``heavy`` on shows the first
generation where the rule would have slept differently. Up to that generation the run is bit for bit the
committed one; after it, only a new run tells. Runs ``../test_policy_v11`` (suite seeds 0-9, 10-19, held-out).

    python docs/benchmarks/backoff_heavy_v12/replay.py [HEAVY]   (default 1.0)
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

from shaped_es.guides.label_budget import LabelBudget

ROOT = Path(__file__).resolve().parent.parent / "test_policy_v11"
PATIENCE, MAX_SLEEP = 8, 32  # the committed runs' shaping.backoff_after, backoff_max


def replay(rows: list[dict], heavy: float) -> list[int]:
    budget, awake = LabelBudget(PATIENCE, MAX_SLEEP, heavy=heavy), []
    for r in rows:
        awake.append(int(budget.begin()))
        if awake[-1] and r.get("candidate_accepted") not in (None, ""):
            spread = float(r["train_reward_max"]) - float(r["train_reward_min"])
            budget.judge(r["candidate_accepted"] in ("1", "1.0"), float(r["candidate_gain"]),
                         float(r["train_reward_mean"]), spread=spread)
    return awake


def main() -> None:
    heavy = float(sys.argv[1]) if len(sys.argv) > 1 else 1.0
    out = {"heavy": heavy, "runs": 0, "changed": []}
    for p in sorted(ROOT.glob("*/*/runs/shaped_s*/metrics.csv")):
        if p.parts[-5] not in ("suite", "suite_10_19", "heldout"):
            continue
        with p.open(newline="") as fh:
            rows = list(csv.DictReader(fh))
        actual = [int(r["shaping_awake"]) for r in rows]
        old, new = replay(rows, 0.0), replay(rows, heavy)
        if old != actual:
            raise SystemExit(f"{p}: the replay does not reproduce the run's schedule")
        out["runs"] += 1
        if new != old:
            g = next(i for i, (a, b) in enumerate(zip(old, new)) if a != b)
            out["changed"].append({"run": str(p.parent.relative_to(ROOT)), "first_generation": g,
                                   "accepted_before": sum(r["candidate_accepted"] in ("1", "1.0") for r in rows[:g]),
                                   "accepted_in_run": sum(r["candidate_accepted"] in ("1", "1.0") for r in rows)})
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
