"""Per seed, a held-out body's shaped runs with ``revert_paired`` against the default's runs of the same seeds:
generations to the threshold (censored at the budget + 1), the late test reward (mean of the last 10
generations), jumps accepted and undone. A run that undid no jump is the default's run to the last digit (the
``undo`` row's episodes are not recorded for M_phi), so those pairs are equal. Prints JSON.

    python heldout_compare.py NEW_RUNS OLD_RUNS THRESHOLD GENERATIONS [OLD_PREFIX]

NEW_RUNS / OLD_RUNS: a benchmark's ``runs`` folders (``shaped_sK``; OLD_PREFIX names the old runs' method,
default ``shaped``)."""
import csv
import json
import sys
from pathlib import Path

import numpy as np


def one(path: Path, thr: float, budget: int) -> dict | None:
    f = path / "metrics.csv"
    if not f.exists():
        return None
    rows = list(csv.DictReader(f.open(newline="")))
    t = np.array([float(r["test_reward_mean"]) for r in rows])  # (G,)
    hit = np.flatnonzero(t >= thr)
    return {"gens": int(hit[0]) + 1 if hit.size else budget + 1, "late": float(t[-10:].mean()),
            "accepted": sum(r.get("candidate_accepted") == "1" for r in rows),
            "undone": sum(r.get("jump_reverted") == "1" for r in rows), "generations": len(rows)}


def main(new: str, old: str, thr: str, budget: str, prefix: str = "shaped") -> dict:
    thr_f, b = float(thr), int(budget)
    seeds = sorted(int(p.name.rsplit("_s", 1)[1]) for p in Path(new).glob("shaped_s*"))
    per = {s: (one(Path(new) / f"shaped_s{s}", thr_f, b), one(Path(old) / f"{prefix}_s{s}", thr_f, b)) for s in seeds}
    pairs = [(n, o) for n, o in per.values() if n and o]
    return {"seeds": len(pairs), "threshold": thr_f, "budget": b,
            "gens_new": float(np.mean([n["gens"] for n, _ in pairs])), "gens_old": float(np.mean([o["gens"] for _, o in pairs])),
            "solved_new": sum(n["gens"] <= b for n, _ in pairs), "solved_old": sum(o["gens"] <= b for _, o in pairs),
            "late_new": float(np.mean([n["late"] for n, _ in pairs])), "late_old": float(np.mean([o["late"] for _, o in pairs])),
            "undone": sum(n["undone"] for n, _ in pairs), "runs_with_undone": sum(n["undone"] > 0 for n, _ in pairs),
            "per_seed": {s: {"new": n, "old": o} for s, (n, o) in per.items()}}


if __name__ == "__main__":
    json.dump(main(*sys.argv[1:]), sys.stdout, indent=1)
