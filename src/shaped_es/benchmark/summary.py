"""Across-seed summary of runs grouped by method (``summary.json`` of a benchmark).

Per method (seeds pooled; intervals are Student-t, ``report/stats.py``):

- ``final_test_reward_mean`` / ``final_test_reward_ci`` ([lo, hi]): the last test evaluation of each seed
  (ES: the generation's best member over the test episodes; PPO: its deterministic policy);
- ``generations_to_target``, ``wall_time_to_target_s``, ``cpu_time_to_target_s``, ``env_steps_to_target``:
  mean over the seeds that reached the target of the first evaluation with a test reward >= target,
  where target = the best final mean among the baselines (every method but ``shaped``; without
  ``shaped`` in the set: the best final mean of all), ``reached_target`` = how many seeds did;
- ``wall_time_s``, ``cpu_time_s``, ``env_steps``, ``generations``: cost of a whole run, mean over seeds;
- ``time_split_s``: per-phase seconds (``gen_time_s``, ``rollout_time_s`` and every ``time_*_s``
  column) summed over a run's generations, mean over seeds.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

from shaped_es.config import RunConfig
from shaped_es.report.plots import load_metrics
from shaped_es.report.stats import t_interval
from shaped_es.store import RunStore, StoreError

Metrics = dict[str, np.ndarray]
REFERENCE = "shaped"  # the paper's method: the target is the best of the *other* methods
PHASE_COLUMN = re.compile(r"^(time_.+_s|gen_time_s|rollout_time_s)$")


def group_runs(run_dirs) -> tuple[dict[str, list[Path]], dict[str, RunConfig]]:
    """Run directories grouped by the method in their ``config.yaml`` (first-seen order), and one config
    per method (the first run's)."""
    groups: dict[str, list[Path]] = {}
    configs: dict[str, RunConfig] = {}
    for d in run_dirs:
        store = RunStore(d)
        cfg = store.read_config()
        if not store.metrics_path.is_file():
            raise StoreError(f"{d} has no metrics.csv yet")
        groups.setdefault(cfg.method, []).append(Path(d))
        configs.setdefault(cfg.method, cfg)
    return groups, configs


def load_runs(dirs: list[Path], generations: int | None = None) -> list[Metrics]:
    """Each run's metrics columns, cut to its first ``generations`` rows if given."""
    out = []
    for d in dirs:
        m = load_metrics(d)
        if m and generations is not None:
            keep = m["generation"] < generations  # (rows,)
            m = {k: v[keep] for k, v in m.items()}
        if m:
            out.append(m)
    return out


def last_finite(v: np.ndarray) -> float:
    ok = np.flatnonzero(np.isfinite(v))
    return float(v[ok[-1]]) if ok.size else math.nan


def first_reach(m: Metrics, target: float) -> dict | None:
    """Costs at the first test evaluation reaching ``target`` (None if never)."""
    test = m.get("test_reward_mean")
    if test is None or not math.isfinite(target):
        return None
    hit = np.flatnonzero(np.isfinite(test) & (test >= target))
    if not hit.size:
        return None
    i = int(hit[0])
    return {"generations": float(m["generation"][i] + 1), "wall_time_s": float(m["wall_time_s"][i]),
            "cpu_time_s": float(m["cpu_time_s"][i]), "env_steps": float(m["env_steps"][i])}


def _mean(values) -> float:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=np.float64)
    return float(v.mean()) if v.size else math.nan


def final_rewards(runs: list[Metrics]) -> list[float]:
    return [last_finite(m.get("test_reward_mean", np.full(1, np.nan))) for m in runs]


def summarize_method(runs: list[Metrics], target: float, level: float) -> dict:
    finals = final_rewards(runs)
    mean, half = t_interval(finals, level)
    reached = [r for r in (first_reach(m, target) for m in runs) if r is not None]
    phases = sorted({k for m in runs for k in m if PHASE_COLUMN.match(k)})
    out = {
        "seeds": len(runs),
        "final_test_reward_mean": mean,
        "final_test_reward_ci": [mean - half, mean + half] if math.isfinite(half) else None,
        "final_test_reward_per_seed": finals,
        "best_test_reward_mean": _mean(last_finite(m["test_reward_best_so_far"]) for m in runs
                                       if "test_reward_best_so_far" in m),
        "reached_target": f"{len(reached)}/{len(runs)}",
        "generations_to_target": _mean(r["generations"] for r in reached),
        "wall_time_to_target_s": _mean(r["wall_time_s"] for r in reached),
        "cpu_time_to_target_s": _mean(r["cpu_time_s"] for r in reached),
        "env_steps_to_target": _mean(r["env_steps"] for r in reached),
        "generations": _mean(float(len(m["generation"])) for m in runs),
        "wall_time_s": _mean(last_finite(m["wall_time_s"]) for m in runs),
        "cpu_time_s": _mean(last_finite(m["cpu_time_s"]) for m in runs),
        "env_steps": _mean(last_finite(m["env_steps"]) for m in runs),
        "time_split_s": {k: _mean(float(np.nansum(m[k])) for m in runs if k in m) for k in phases},
    }
    for col in ("mphi_train_loss", "mphi_test_loss"):
        if any(col in m for m in runs):
            out[f"final_{col}"] = _mean(last_finite(m[col]) for m in runs if col in m)
    return out


def pick_target(finals: dict[str, float], reference: str = REFERENCE) -> dict:
    """The best baseline's final mean test reward (baselines: all methods but ``reference``)."""
    pool = {k: v for k, v in finals.items() if k != reference and math.isfinite(v)}
    if not pool:
        pool = {k: v for k, v in finals.items() if math.isfinite(v)}
    if not pool:
        return {"value": math.nan, "method": None, "reference": reference}
    best = max(pool, key=pool.get)
    return {"value": pool[best], "method": best, "reference": reference if reference in finals else None}


def summarize(groups: dict[str, list[Metrics]], level: float = 0.95, reference: str = REFERENCE) -> dict:
    finals = {k: t_interval(final_rewards(runs), level)[0] for k, runs in groups.items()}
    target = pick_target(finals, reference)
    methods = {k: summarize_method(runs, target["value"], level) for k, runs in groups.items()}
    return clean_json({"ci_level": level, "target": target, "methods": methods})


def method_settings(cfg: RunConfig) -> dict:
    """The settings a reader needs to tell the runs apart (ablation switches included)."""
    return {"env": cfg.env, "env_kwargs": cfg.env_kwargs, "pairs": cfg.es.pairs, "sigma": cfg.es.sigma,
            "alpha": cfg.es.alpha, "eta": cfg.shaping.eta, "episodes": cfg.rollout.episodes,
            "test_episodes": cfg.rollout.test_episodes, "executor": cfg.executor, "workers": cfg.workers}


def clean_json(v):
    """NaN/inf -> None, numpy scalars -> Python, recursively (summary.json stays valid JSON)."""
    if isinstance(v, dict):
        return {str(k): clean_json(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [clean_json(x) for x in v]
    if isinstance(v, (float, np.floating)):
        return float(v) if math.isfinite(v) else None
    if isinstance(v, np.integer):
        return int(v)
    return v
