"""The new user's differential-drive robot (``../heldout_diffbot_v14/diffbot.py``) with and without chunk targets
in the label probe, beside Vanilla-ES: per seed, generations to 8.5 (censored at the budget + 1), whether the
probe chose chunk targets, the candidates accepted; per arm the censored mean, and the ratios with 95%
percentile-bootstrap intervals, the seeds resampled in pairs.

    python docs/benchmarks/probe_chunk_v15/compare_diffbot.py DEFAULT_DIR OFF_DIR VANILLA_DIR > diffbot.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from compare import metrics, paired_ratio, to_threshold  # this folder's compare.py

THRESHOLD = 8.5  # 0.9 x the scripted controller's 9.58 (../heldout_diffbot_v14/measure_baselines.py)


def arm(d: Path) -> dict:
    runs = sorted((d / "runs").iterdir(), key=lambda p: int(p.name.rsplit("_s", 1)[1]))
    gens, chunk, accepted = [], [], []
    for r in runs:
        m = metrics(r)
        gens.append(to_threshold(m, THRESHOLD))
        probe = r / "label_probe.json"
        chunk.append(json.loads(probe.read_text()).get("chunk") if probe.exists() else None)
        accepted.append(int(np.nansum(m["candidate_accepted"] == 1)) if "candidate_accepted" in m else 0)
    return {"seeds": [int(r.name.rsplit("_s", 1)[1]) for r in runs], "generations": gens, "chunk": chunk,
            "candidates_accepted": accepted, "mean": float(np.mean(gens))}


def main(default: str, off: str, vanilla: str) -> dict:
    out = {"default": arm(Path(default)), "probe_chunk_0": arm(Path(off)), "vanilla": arm(Path(vanilla))}
    a, b, v = (np.array(out[k]["generations"], float) for k in ("default", "probe_chunk_0", "vanilla"))
    out["default_over_probe_chunk_0"] = paired_ratio(a, b)
    out["default_over_vanilla"] = paired_ratio(a, v)
    out["probe_chunk_0_over_vanilla"] = paired_ratio(b, v)
    return out


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    json.dump(main(*sys.argv[1:4]), sys.stdout, indent=1)
    print()
