"""A third query clip in the label probe (``shaping.inverse_dynamics.probe_clip_long``, now 4) against the
previous default (``../probe_chunk_v15``'s runs, the same seeds): per body and seed, generations to the threshold
(censored at the budget + 1), the variant the probe chose, whether it took clip 4, and whether a run whose probe
did not is row for row the previous one (its ``train_reward_mean`` column); per body the censored means, the
last 10 evaluations' mean test reward, and the paired-bootstrap ratio new / previous.

    python docs/benchmarks/probe_clip_long_v16/compare.py suite SUITE_DIR > suite.json
    python docs/benchmarks/probe_clip_long_v16/compare.py runs NEW_RUNS PREVIOUS_RUNS THRESHOLD > body.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "probe_chunk_v15"))
from compare import metrics, paired_ratio, to_threshold  # noqa: E402  (probe_chunk_v15/compare.py)
from shaped_es.benchmark.summary import threshold_of  # noqa: E402
from shaped_es.guides.probe_variants import variant_name  # noqa: E402

PREV = HERE.parent / "probe_chunk_v15" / "suite"


def late(m: dict[str, np.ndarray]) -> float:
    tests = m["test_reward_mean"][np.isfinite(m["test_reward_mean"])]  # (evaluations,)
    return float(np.mean(tests[-10:]))


def body(new: Path, prev: Path, thr: float) -> dict:
    seeds = sorted(int(p.name.split("_s")[1]) for p in new.glob("shaped_s*"))
    rows = {k: [] for k in ("new", "previous", "late_new", "late_previous", "chosen", "clip4", "same")}
    for s in seeds:
        m, old = metrics(new / f"shaped_s{s}"), metrics(prev / f"shaped_s{s}")
        p = json.loads((new / f"shaped_s{s}" / "label_probe.json").read_text())
        name = variant_name(p["frame"], p["query_clip"], p.get("chunk"))
        rows["new"].append(to_threshold(m, thr))
        rows["previous"].append(to_threshold(old, thr))
        rows["late_new"].append(late(m))
        rows["late_previous"].append(late(old))
        rows["chosen"].append(name)
        rows["clip4"].append(p["query_clip"] == 4.0)
        n = min(len(m["train_reward_mean"]), len(old["train_reward_mean"]))
        rows["same"].append(bool(np.array_equal(m["train_reward_mean"][:n], old["train_reward_mean"][:n],
                                                equal_nan=True)))
    a, b = np.array(rows["new"], float), np.array(rows["previous"], float)
    return {"seeds": seeds, "threshold": thr, **rows,
            "mean": {"new": float(a.mean()), "previous": float(b.mean()),
                     "late_new": float(np.mean(rows["late_new"])), "late_previous": float(np.mean(rows["late_previous"]))},
            "new_over_previous": paired_ratio(a, b)}


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[0] == "suite":
        root = Path(args[1])
        out = {t.name: body(t / "runs", PREV / t.name / "runs", threshold_of(t.name)[0])
               for t in sorted(p for p in root.iterdir() if p.is_dir())}
    else:
        out = body(Path(args[1]), Path(args[2]), float(args[3]))
    json.dump(out, sys.stdout, indent=1)
    print()
