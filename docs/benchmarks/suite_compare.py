"""Per task: variant studies' runs beside suite_waypoints_v6's (the default, Vanilla-ES, CMA-ES) on the
same seeds: generations to the threshold (censored mean: an unsolved run counts budget + 1), seeds
solved, the late test reward (each run's mean over its last 10 generations; mean over seeds with a 95%
bootstrap interval), candidates accepted (in all, and from generation 30 on), jumps undone, awake
generations. Prints JSON.

    python docs/benchmarks/suite_compare.py LABEL=DIR[:METHOD] ...   (stdlib + NumPy + PyYAML)

DIR is a `shaped-es suite run --out` directory (task folders with runs/METHOD_sK/metrics.csv), METHOD
its runs' method (default shaped). A study's tasks without runs are left out; a task folder without
runs is an error. `--first-seed 10` studies compare with `suite_waypoints_v6/seeds_10_19` where it has
the task (the v6 columns then read seeds 10-19).
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np
import yaml

HERE = Path(__file__).resolve().parent
V6 = HERE / "suite_waypoints_v6"
sys.path.insert(0, str(V6))
from stats import THRESHOLDS  # noqa: E402

BUDGET = yaml.safe_load((V6 / "suite.yaml").read_text())["tasks"]


def one(path: Path, thr: float, budget: int) -> dict:
    """One run's metrics.csv: generations to ``thr`` (budget + 1 if never), late reward, jumps."""
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    t = np.array([float(r["test_reward_mean"]) for r in rows])  # (G,)
    hit = np.flatnonzero(t >= thr)
    acc = [int(r["generation"]) for r in rows if r.get("candidate_accepted") == "1"]
    return {"gens": int(hit[0]) + 1 if hit.size else budget + 1, "late": float(t[-10:].mean()),
            "accepted": len(acc), "accepted_from_30": sum(g >= 30 for g in acc),
            "reverted": sum(r.get("jump_reverted") == "1" for r in rows),
            "awake": sum(r.get("shaping_awake") == "1" for r in rows)}


def arm(task_dir: Path, method: str, task: str, rng) -> dict | None:
    """One method's runs of one task (None: no runs there)."""
    runs = sorted(task_dir.glob(f"runs/{method}_s*/metrics.csv"))
    if not runs:
        return None
    per = [one(p, THRESHOLDS[task], BUDGET[task]) for p in runs]
    g = np.array([p["gens"] for p in per])  # (S,)
    late = np.array([p["late"] for p in per])  # (S,)
    boot = rng.choice(late, size=(10_000, late.size)).mean(1)  # (B,)
    return {"seeds": len(per), "solved": int((g <= BUDGET[task]).sum()), "gens": float(g.mean()),
            "gens_per_seed": g.tolist(), "late_reward": float(late.mean()),
            "late_reward_ci": [float(x) for x in np.percentile(boot, [2.5, 97.5])],
            **{k: int(sum(p[k] for p in per)) for k in ("accepted", "accepted_from_30", "reverted")},
            "awake_mean": float(np.mean([p["awake"] for p in per]))}


def compare(studies: dict[str, tuple[Path, str]]) -> dict:
    """``studies``: label -> (suite directory, method). Per task, v6's three methods and each study."""
    rng = np.random.default_rng(0)
    out: dict = {}
    for task in BUDGET:
        found = {lab: sorted((d / task).glob(f"runs/{m}_s*/metrics.csv")) for lab, (d, m) in studies.items()}
        for lab, (d, m) in studies.items():
            if not found[lab] and (d / task).is_dir():  # a study of this task whose runs are missing
                sys.exit(f"suite_compare.py: {d / task} holds no runs/{m}_s*/metrics.csv")
        seeds = [int(p.parent.name.rsplit("_s", 1)[1]) for runs in found.values() for p in runs]
        if not seeds:
            continue
        base = V6 / "seeds_10_19" if min(seeds) >= 10 and (V6 / "seeds_10_19" / task).is_dir() else V6
        res = {("v6 default" if m == "shaped" else m): r for m in ("shaped", "vanilla", "cmaes")
               if (r := arm(base / task, m, task, rng)) is not None}
        for lab, (d, m) in studies.items():
            if found[lab]:
                res[lab] = arm(d / task, m, task, rng)
        out[task] = res
    return out


def parse(args: list[str]) -> dict[str, tuple[Path, str]]:
    studies = {}
    for a in args:
        label, sep, rest = a.partition("=")
        if not sep or not label:
            sys.exit(f"suite_compare.py: expected LABEL=DIR[:METHOD], got {a!r}")
        d, _, method = rest.partition(":")
        if not Path(d).is_dir():
            sys.exit(f"suite_compare.py: {d} is not a directory")
        studies[label] = (Path(d), method or "shaped")
    return studies


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    print(json.dumps(compare(parse(sys.argv[1:])), indent=1))
