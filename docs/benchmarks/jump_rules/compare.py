"""Per task: each jump-rule variant's shaped runs beside suite_waypoints_v6's (the default, Vanilla-ES,
CMA-ES): generations to the threshold (censored mean: an unsolved run counts budget + 1), seeds solved,
the late test reward (each run's mean over its last 10 generations; mean over seeds with a 95% bootstrap
interval), candidates accepted (in all, and from generation 30 on), jumps undone, awake generations.
Prints JSON (``../suite_compare.py`` does the reading).

    python docs/benchmarks/jump_rules/compare.py   (stdlib + NumPy + PyYAML)
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))
from suite_compare import compare  # noqa: E402

VARIANTS = {"z2": "accept_margin=2", "rev1": "revert_margin=1", "rev1u": "revert_margin=1",
            "rev2": "revert_margin=2"}

if __name__ == "__main__":
    print(json.dumps(compare({f"{v} ({label})": (HERE / v, "shaped") for v, label in VARIANTS.items()}), indent=1))
