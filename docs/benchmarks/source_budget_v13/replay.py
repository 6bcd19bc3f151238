"""A budget per rival label source, replayed (not built): which accepted candidates would a rule have lost that
puts a rival (the waypoint frame 1, the servo 2, the shooting labels 3; ``guides/rival.py``) to sleep for the
rest of the run once it has been judged K times without a win while the other sources won W or more?

Reads every committed suite and held-out run of ``../test_policy_v11`` (shaped, its per-rival gain columns);
per (K, W): the rival-generations the rule would save, the accepted candidates of the slept rival after that
point (the wins lost), and those of them before the run's first test reward at its threshold.

    python docs/benchmarks/source_budget_v13/replay.py > replay.txt
"""

import csv
import itertools
from collections import defaultdict
from pathlib import Path

import yaml

from shaped_es.benchmark.summary import builtin_threshold

ROOT = Path(__file__).resolve().parent.parent / "test_policy_v11"
COLUMN = {1: "rival_gain", 2: "servo_gain", 3: "shoot_gain"}
HELD_OUT = {"myenvs:Tractor-v0": -6.0, "myenvs:Hover3D-v0": 8.5, "myboat:MyBoat-v0": 8.5}  # their thresholds


def threshold(task_dir: Path) -> float:
    spec = yaml.safe_load((task_dir / "benchmark.yaml").read_text())
    if spec.get("threshold") is not None:
        return float(spec["threshold"])
    known = builtin_threshold(spec["env"])
    return known[0] if known else HELD_OUT.get(spec["env"], float("inf"))


def main() -> None:
    paths = [p for p in sorted(ROOT.glob("*/*/runs/shaped_s*/metrics.csv"))
             if p.parts[-5] in ("suite", "suite_10_19", "heldout")]
    runs = []
    for p in paths:
        rows = list(csv.DictReader(p.open(newline="")))
        thr = threshold(p.parents[2])
        reach = next((int(r["generation"]) for r in rows if r["test_reward_mean"]
                      and float(r["test_reward_mean"]) >= thr), 10**9)
        runs.append((p.parts[-4], [r for r in rows if r["candidate_accepted"] not in ("", None)], reach))
    for K, W in itertools.product((6, 10, 15), (2, 4)):
        saved, lost, early, total = (defaultdict(int) for _ in range(4))
        for task, rows, reach in runs:
            for v, col in COLUMN.items():
                if not rows or col not in rows[0]:
                    continue
                judged = [r for r in rows if r.get(col) not in ("", None)]
                total[task] += len(judged)
                own = others = 0
                dead = None
                for i, r in enumerate(judged):
                    won = r["candidate_accepted"] in ("1", "1.0")
                    own += int(won and r["candidate_rival"] == str(v))
                    others += int(won and r["candidate_rival"] != str(v))
                    if dead is None and i + 1 >= K and own == 0 and others >= W:
                        dead = i + 1
                if dead is None:
                    continue
                saved[task] += len(judged) - dead
                after = [r for r in judged[dead:] if r["candidate_accepted"] in ("1", "1.0")
                         and r["candidate_rival"] == str(v)]
                lost[task] += len(after)
                early[task] += sum(int(r["generation"]) < reach for r in after)
        print(f"K={K} W={W}: saves {sum(saved.values())} of {sum(total.values())} rival-generations; wins lost "
              f"{sum(lost.values())}, before the threshold {sum(early.values())}; per task (saved, lost, before): "
              + ", ".join(f"{t} {saved[t]}/{lost[t]}/{early[t]}" for t in sorted(total) if saved[t]))


if __name__ == "__main__":
    main()
