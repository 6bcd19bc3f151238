"""UR5Reach-v0's seeds 10-19 with and without chunk variants in the label probe (``ur5_10_19/``): per seed,
generations to 40 (censored at 61), the last 10 generations' mean test reward, whether the probe chose chunk
targets; means and the paired-bootstrap ratio of the generations.

    python docs/benchmarks/probe_chunk_v15/compare_ur5.py > ur5_10_19.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from compare import metrics, paired_ratio, to_threshold  # this folder's compare.py

HERE = Path(__file__).resolve().parent


def arm(d: Path) -> dict:
    gens, late, chunk = [], [], []
    for s in range(10, 20):
        run = d / f"shaped_s{s}"
        m = metrics(run)
        gens.append(to_threshold(m, 40.0))
        tests = m["test_reward_mean"][np.isfinite(m["test_reward_mean"])]  # (evaluations,)
        late.append(float(np.mean(tests[-10:])))
        chunk.append(json.loads((run / "label_probe.json").read_text()).get("chunk"))
    return {"generations": gens, "late_reward": late, "chunk": chunk, "mean": float(np.mean(gens)),
            "late_mean": float(np.mean(late))}


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    out = {k: arm(HERE / "ur5_10_19" / k) for k in ("default", "probe_chunk_0")}
    out["default_over_probe_chunk_0"] = paired_ratio(np.array(out["default"]["generations"], float),
                                                     np.array(out["probe_chunk_0"]["generations"], float))
    json.dump(out, sys.stdout, indent=1)
    print()
