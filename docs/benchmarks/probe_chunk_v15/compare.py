"""Chunk targets offered to the label probe (``shaping.inverse_dynamics.probe_chunk``, 4) against the previous
default (``../probe_candidate_v14/suite``, the same seeds, made on the same machine): per task and seed,
generations to the threshold (censored at the budget + 1), whether the probe chose chunk targets, and whether a
run whose probe chose as before is row for row the previous one (its ``train_reward_mean`` column). Per task,
the censored means and the ratios new / previous and new / Vanilla-ES / CMA-ES (``../test_policy_v11``'s runs,
whose code is unchanged), with 95% percentile-bootstrap intervals over the seeds resampled in pairs.

    python docs/benchmarks/probe_chunk_v15/compare.py [--previous SUITE_DIR] NEW_SUITE_DIR [...] > compare.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from shaped_es.benchmark.summary import threshold_of, time_to_threshold
from shaped_es.report.plots import load_metrics

HERE = Path(__file__).resolve().parent
PREV, BASE = HERE.parent / "probe_candidate_v14" / "suite", HERE.parent / "test_policy_v11" / "suite"


def metrics(run: Path) -> dict[str, np.ndarray]:
    """A run's ``metrics.csv`` as columns (the report's reader)."""
    return load_metrics(run)


def to_threshold(m: dict[str, np.ndarray], thr: float) -> int:
    """Generations done when the test reward first reached ``thr`` (budget + 1 if never): the report's censored
    count (``summary.time_to_threshold``)."""
    return int(time_to_threshold([m], thr)["generations"]["per_seed"][0])


def paired_ratio(a: np.ndarray, b: np.ndarray, n: int = 10_000, seed: int = 0) -> list[float]:
    """mean(a) / mean(b) and its 95% percentile-bootstrap interval, the seeds resampled in pairs."""
    rng = np.random.default_rng(seed)
    idx = rng.integers(0, len(a), size=(n, len(a)))  # (n, seeds)
    r = a[idx].mean(1) / b[idx].mean(1)
    return [float(a.mean() / b.mean()), float(np.percentile(r, 2.5)), float(np.percentile(r, 97.5))]


def main(dirs: list[str]) -> dict:
    out = {}
    for d in dirs:
        for task in sorted(p for p in Path(d).iterdir() if p.is_dir()):
            env, thr = task.name, threshold_of(task.name)[0]
            seeds = sorted(int(p.name.split("_s")[1]) for p in (task / "runs").glob("shaped_s*"))
            new, prev, van, cma, chunk, same = [], [], [], [], [], []
            for s in seeds:
                m, old = metrics(task / "runs" / f"shaped_s{s}"), metrics(PREV / env / "runs" / f"shaped_s{s}")
                new.append(to_threshold(m, thr))
                prev.append(to_threshold(old, thr))
                van.append(to_threshold(metrics(BASE / env / "runs" / f"vanilla_s{s}"), thr))
                cma.append(to_threshold(metrics(BASE / env / "runs" / f"cmaes_s{s}"), thr))
                probe = json.loads((task / "runs" / f"shaped_s{s}" / "label_probe.json").read_text())
                chunk.append(probe.get("chunk"))
                same.append(bool(np.array_equal(m["train_reward_mean"], old["train_reward_mean"], equal_nan=True)))
            a, b = np.array(new, float), np.array(prev, float)
            out[env] = {"seeds": seeds, "threshold": thr, "new": new, "previous": prev, "vanilla": van, "cmaes": cma,
                        "chunk": chunk, "same_as_previous": same,
                        "mean": {"new": a.mean(), "previous": b.mean(), "vanilla": float(np.mean(van)),
                                 "cmaes": float(np.mean(cma))},
                        "new_over_previous": paired_ratio(a, b),
                        "new_over_vanilla": paired_ratio(a, np.array(van, float)),
                        "new_over_cmaes": paired_ratio(a, np.array(cma, float))}
    ratios = [v["new_over_vanilla"][0] for v in out.values()]
    prev_r = [v["mean"]["previous"] / v["mean"]["vanilla"] for v in out.values()]
    out["geomean_over_vanilla"] = {"new": float(np.exp(np.mean(np.log(ratios)))),
                                   "previous": float(np.exp(np.mean(np.log(prev_r))))}
    return out


if __name__ == "__main__":
    args = sys.argv[1:]
    if args[:1] == ["--previous"]:  # another previous default's suite folder (the same layout)
        PREV, args = Path(args[1]).resolve(), args[2:]
    json.dump(main(args), sys.stdout, indent=1)
    print()
