"""The heavy-loss back-off's first version (``shaping.backoff_heavy=1``, heavy losses counted after a first win
too) against the same code without it, seed by seed (the runs in ``first_version/``).

The runs without it are ``../test_policy_v11``'s (same seeds, same code but for the rule: a run whose budget
never sees a heavy loss before its first sleep trains bit for bit as there). Per task: how many runs are
identical in every test reward, the generation where the others first differ (a changed sleep or reward),
generations to the env's threshold (censored at the budget + 1), the late test reward (the mean of the last
10 generations) paired per seed with a 95% bootstrap interval, awake generations and accepted candidates.

    python docs/benchmarks/backoff_heavy_v12/compare.py > docs/benchmarks/backoff_heavy_v12/first_version/compare.json
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent / "first_version"
OLD = HERE.parent.parent / "test_policy_v11"
# where the new runs are, where the old ones are, and the threshold (None: the registered one)
GROUPS = {"suite": ("suite", None), "heldout": ("heldout", None)}
HELD = {"hover": 8.5, "tractor": -6.0, "drone": None, "boat": 8.5}


def rows(p: Path) -> list[dict]:
    with p.open(newline="") as fh:
        return list(csv.DictReader(fh))


def to_threshold(r: list[dict], t: float) -> int:
    return next((int(x["generation"]) + 1 for x in r if float(x["test_reward_mean"]) >= t), len(r) + 1)


def late(r: list[dict]) -> float:
    return float(np.mean([float(x["test_reward_mean"]) for x in r[-10:]]))


def boot(d: np.ndarray, rng) -> list[float]:
    m = [rng.choice(d, d.size).mean() for _ in range(10_000)]
    return [float(np.percentile(m, 2.5)), float(np.percentile(m, 97.5))]


def threshold(task_dir: Path, held: str | None) -> float | None:
    if held is not None:
        if HELD.get(held) is not None:
            return HELD[held]
        cfg = (next(task_dir.glob("runs/*/config.yaml"))).read_text()
        env = next(ln.split(":", 1)[1].strip() for ln in cfg.splitlines() if ln.startswith("env:"))
    else:
        env = task_dir.name
    import gymnasium as gym

    try:
        return gym.spec(env).reward_threshold
    except Exception:  # a held-out env whose module is not importable here
        return None


def main() -> None:
    import shaped_es  # noqa: F401  registers the suite's envs

    rng = np.random.default_rng(0)
    out = {}
    for group in ("suite", "heldout"):
        for task_dir in sorted((HERE / group).iterdir()):
            if not (task_dir / "runs").is_dir():
                continue
            held = task_dir.name if group == "heldout" else None
            old_dir = OLD / group / task_dir.name / "runs"
            t = threshold(task_dir, held)
            per, diffs = [], []
            for run in sorted((task_dir / "runs").glob("shaped_s*"), key=lambda p: int(p.name[8:])):
                a, b = rows(run / "metrics.csv"), rows(old_dir / run.name / "metrics.csv")
                same = len(a) == len(b) and all(x["test_reward_mean"] == y["test_reward_mean"] for x, y in zip(a, b))
                first = next((int(x["generation"]) for x, y in zip(a, b) if x["shaping_awake"] != y["shaping_awake"]
                              or x["test_reward_mean"] != y["test_reward_mean"]), None)
                rec = {"seed": int(run.name[8:]), "identical_rewards": same, "first_difference": first,
                       "late_new": late(a), "late_old": late(b),
                       "awake_new": sum(x["shaping_awake"] == "1" for x in a),
                       "awake_old": sum(x["shaping_awake"] == "1" for x in b),
                       "accepted_new": sum(x["candidate_accepted"] in ("1", "1.0") for x in a),
                       "accepted_old": sum(x["candidate_accepted"] in ("1", "1.0") for x in b)}
                if t is not None:
                    rec["to_threshold_new"], rec["to_threshold_old"] = to_threshold(a, t), to_threshold(b, t)
                per.append(rec)
                diffs.append(rec["late_new"] - rec["late_old"])
            d = np.array(diffs)
            summary = {"runs": len(per), "identical_rewards": sum(r["identical_rewards"] for r in per),
                       "late_new_minus_old": float(d.mean()), "late_interval": boot(d, rng),
                       "awake_new": sum(r["awake_new"] for r in per), "awake_old": sum(r["awake_old"] for r in per),
                       "accepted_new": sum(r["accepted_new"] for r in per),
                       "accepted_old": sum(r["accepted_old"] for r in per), "threshold": t}
            if t is not None:
                summary["to_threshold_mean_new"] = float(np.mean([r["to_threshold_new"] for r in per]))
                summary["to_threshold_mean_old"] = float(np.mean([r["to_threshold_old"] for r in per]))
            out[f"{group}/{task_dir.name}"] = {"summary": summary, "runs": per}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
