"""Which committed runs would the heavy rule change, for each of its numbers? A grid over the losses it waits
for (``label_budget.HEAVY_MIN``: 3, 4) and its threshold H (1, 0.5, 0.3 population spreads), replaying every
committed suite and held-out run's judgements (``../test_policy_v11``, made with the rule off) as
``../backoff_heavy_v12/replay.py`` does. A run changes at its first early sleep, whatever the sleep's length.

    python docs/benchmarks/backoff_heavy_v13/grid.py
"""

import csv
import itertools
import sys
from pathlib import Path

import shaped_es.guides.label_budget as lb

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "backoff_heavy_v12"))
from replay import ROOT, replay as replay_v12  # noqa: E402 - the fourteenth session's replay, one rule's


def replay(rows: list[dict], heavy: float, hmin: int) -> list[int]:
    """``replay_v12`` with ``label_budget.HEAVY_MIN`` set to ``hmin`` for the call."""
    lb.HEAVY_MIN, saved = hmin, lb.HEAVY_MIN
    try:
        return replay_v12(rows, heavy)
    finally:
        lb.HEAVY_MIN = saved


def main() -> None:
    runs = [(p, list(csv.DictReader(p.open(newline="")))) for p in sorted(ROOT.glob("*/*/runs/shaped_s*/metrics.csv"))
            if p.parts[-5] in ("suite", "suite_10_19", "heldout")]
    for hmin, heavy in itertools.product((3, 4), (1.0, 0.5, 0.3)):
        changed = []
        for p, rows in runs:
            if replay(rows, heavy, hmin) != [int(r["shaping_awake"]) for r in rows]:
                accepted = sum(r["candidate_accepted"] in ("1", "1.0") for r in rows)
                changed.append(f"{p.parts[-4]}/{p.parts[-2]} ({accepted} accepted)")
        paying = [c for c in changed if not c.endswith("(0 accepted)")]
        print(f"losses {hmin}, H {heavy}: {len(changed)} of {len(runs)} runs change; paying ones: {paying or 'none'}")


if __name__ == "__main__":
    main()
