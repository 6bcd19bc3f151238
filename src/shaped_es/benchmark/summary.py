"""Across-seed summary of runs grouped by method (``summary.json`` of a benchmark).

Per method, over its seeds:

- ``final_test_reward_mean`` / ``final_test_reward_ci`` ([lo, hi], Student-t) and
  ``final_test_reward_iqm`` / ``final_test_reward_iqm_ci`` (interquartile mean, percentile-bootstrap
  interval; ``report/aggregate.py``) of each seed's last test evaluation (ES: the generation's tested policy,
  ``rollout.test_policy``, over the test episodes; PPO: its deterministic policy);
- ``success_rate`` / ``successes``: the seeds whose test reward reached the threshold at some evaluation;
- ``to_threshold``: ``generations``, ``wall_time_s``, ``cpu_time_s``, ``env_steps`` at each seed's first
  evaluation with test reward >= threshold, **censored**: a seed that never reaches it counts as its own
  run's generations + 1 and as its whole run's wall time / CPU time / env steps (lower bounds), so
  the ``mean`` and ``median`` over all seeds are censored statistics (the median is exact while fewer
  than half the seeds are censored); ``per_seed`` and ``reached`` list each seed;
- ``wall_time_s``, ``cpu_time_s``, ``env_steps``, ``generations``: cost of a whole run, mean over seeds;
- ``shaping`` (methods with candidates): candidates judged / accepted (by label variant), mean gain,
  generations backed off per run, runs without an acceptance (``shaping_summary.py``);
- ``time_split_s``: per-phase seconds (``gen_time_s``, ``rollout_time_s`` and every ``time_*_s``
  column) summed over a run's generations, mean over seeds.

Across methods: ``threshold`` (value and where it comes from: ``--threshold``, the env's default in
``DEFAULT_THRESHOLDS``, else the ``reward_threshold`` of the env's Gymnasium spec, a user's env's included,
else the best baseline's final mean), ``budget_generations``, and
``probability_of_improvement[X][Y]``: P(final reward of a seed of X > one of Y) with a bootstrap
interval and the Mann-Whitney p-value.

Which runs form a method's group, and the settings that tell groups apart: ``grouping.py``.
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np

# grouping runs and the settings that tell them apart: grouping.py (importable from here as before)
from shaped_es.benchmark.grouping import (  # noqa: F401
    ReportWarning,
    group_runs,
    method_settings,
    non_defaults,
    plain,
    report_env,
    run_settings,
    uses,
)
from shaped_es.benchmark.shaping_summary import shaping_summary
from shaped_es.config import RunConfig
from shaped_es.envs.thresholds import (  # noqa: F401 (their home is the env layer; benchmark's names)
    DEFAULT_THRESHOLDS, REWARD_SCALE_KEYS, builtin_threshold, env_threshold, spec_threshold, threshold_of)
from shaped_es.report.aggregate import RESAMPLES, iqm_with_ci, probability_of_improvement, ratio_of_means
from shaped_es.report.plots import load_metrics
from shaped_es.report.stats import t_interval

Metrics = dict[str, np.ndarray]
FALLBACK_SOURCE = "best baseline's final mean test reward"  # the threshold's source where none was given
REFERENCE = "shaped"  # the paper's method: the fallback threshold is the best of the *other* methods
PHASE_COLUMN = re.compile(r"^(time_.+_s|gen_time_s|rollout_time_s)$")
COST_COLUMNS = ("wall_time_s", "cpu_time_s", "env_steps")


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


def first_reach(m: Metrics, threshold: float) -> dict | None:
    """Costs at the first test evaluation reaching ``threshold`` (None if never)."""
    test = m.get("test_reward_mean")
    if test is None or not math.isfinite(threshold):
        return None
    hit = np.flatnonzero(np.isfinite(test) & (test >= threshold))
    if not hit.size:
        return None
    i = int(hit[0])
    return {"generations": float(m["generation"][i] + 1),
            **{k: float(m[k][i]) if k in m else math.nan for k in COST_COLUMNS}}


def time_to_threshold(runs: list[Metrics], threshold: float) -> dict:
    """Per cost, each seed's cost to the first evaluation >= ``threshold``; a seed that never reaches it is
    censored at its own run's budget: the generations it ran + 1 (and its whole cost in the other units),
    so a short run is never credited with a longer run's budget. ``budgets``: each seed's generations."""
    hits = [first_reach(m, threshold) for m in runs]
    out: dict = {"reached": [h is not None for h in hits], "budgets": [run_generations(m) for m in runs]}
    for key in ("generations", *COST_COLUMNS):
        per_seed = [h[key] if h is not None else
                    (float(run_generations(m) + 1) if key == "generations"
                     else last_finite(m.get(key, np.full(1, np.nan))))
                    for h, m in zip(hits, runs)]
        v = np.asarray([x for x in per_seed if math.isfinite(x)], dtype=np.float64)
        out[key] = {"mean": float(v.mean()) if v.size else math.nan,
                    "median": float(np.median(v)) if v.size else math.nan, "per_seed": per_seed}
    return out


def _mean(values) -> float:
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=np.float64)
    return float(v.mean()) if v.size else math.nan


def final_rewards(runs: list[Metrics]) -> list[float]:
    return [last_finite(m.get("test_reward_mean", np.full(1, np.nan))) for m in runs]


LATE_EVALUATIONS = 10  # the late reward: each seed's mean over its last this many test evaluations


def late_rewards(runs: list[Metrics]) -> list[float]:
    """Each seed's mean test reward over its last :data:`LATE_EVALUATIONS` evaluations (fewer where it has
    fewer): steadier than the last one alone, which a new user's lander showed swinging by seeds' luck."""
    out = []
    for m in runs:
        v = np.asarray(m.get("test_reward_mean", np.full(1, np.nan)), np.float64)
        v = v[np.isfinite(v)][-LATE_EVALUATIONS:]  # (<= LATE_EVALUATIONS,)
        out.append(float(v.mean()) if v.size else math.nan)
    return out


def run_generations(m: Metrics) -> int:
    g = m.get("generation")
    return int(np.nanmax(g)) + 1 if g is not None and np.isfinite(g).any() else 0


def summarize_method(runs: list[Metrics], threshold: float, level: float, resamples: int = RESAMPLES) -> dict:
    finals = final_rewards(runs)
    mean, half = t_interval(finals, level)
    robust = iqm_with_ci(finals, level, resamples)
    late = late_rewards(runs)
    late_robust = iqm_with_ci(late, level, resamples)
    tt = time_to_threshold(runs, threshold)
    successes = int(sum(tt["reached"]))
    phases = sorted({k for m in runs for k in m if PHASE_COLUMN.match(k)})
    out = {
        "seeds": len(runs),
        "final_test_reward_mean": mean,
        "final_test_reward_ci": [mean - half, mean + half] if math.isfinite(half) else None,
        "final_test_reward_iqm": robust["iqm"],
        "final_test_reward_iqm_ci": robust["ci"],
        "final_test_reward_per_seed": finals,
        "late_test_reward_iqm": late_robust["iqm"],  # each seed's last LATE_EVALUATIONS evaluations' mean
        "late_test_reward_iqm_ci": late_robust["ci"],
        "late_test_reward_per_seed": late,
        "best_test_reward_mean": _mean(last_finite(m["test_reward_best_so_far"]) for m in runs
                                       if "test_reward_best_so_far" in m),
        "successes": successes,
        "success_rate": successes / len(runs) if runs else math.nan,
        "to_threshold": tt,
        "generations": _mean(float(len(m["generation"])) for m in runs),
        "wall_time_s": _mean(last_finite(m["wall_time_s"]) for m in runs),
        "cpu_time_s": _mean(last_finite(m["cpu_time_s"]) for m in runs),
        "env_steps": _mean(last_finite(m["env_steps"]) for m in runs),
        "time_split_s": {k: _mean(float(np.nansum(m[k])) for m in runs if k in m) for k in phases},
    }
    shaping = shaping_summary(runs)  # candidates judged / accepted by variant, back-off (shaped methods)
    if shaping is not None:
        out["shaping"] = shaping
    for col in ("mphi_train_loss", "mphi_fig5_test_loss", "mphi_fit_test_loss", "mphi_test_loss"):
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


def resolve_threshold(threshold: float | None, finals: dict[str, float], cfg: RunConfig | None = None,
                      reference: str = REFERENCE) -> dict:
    """{"value", "source", ...}: ``threshold`` if given, else the env's default, else the best baseline's
    final mean test reward (then also ``method`` and ``reference``)."""
    if threshold is not None:
        return {"value": float(threshold), "source": "--threshold"}
    default = env_threshold(cfg)
    if default is not None:
        return {"value": default[0], "source": default[1]}
    return {**pick_target(finals, reference), "source": FALLBACK_SOURCE}


def summarize(groups: dict[str, list[Metrics]], level: float = 0.95, reference: str = REFERENCE,
              threshold: float | None = None, budget: int | None = None, config: RunConfig | None = None,
              resamples: int = RESAMPLES) -> dict:
    """The summary of ``groups`` (method -> each seed's metrics). ``threshold``: see
    ``resolve_threshold`` (``config``: any run's, for the env's default); ``budget``: generations per
    run, as reported (default: the longest run's; each run is censored at its own, ``time_to_threshold``)."""
    finals = {k: t_interval(final_rewards(runs), level)[0] for k, runs in groups.items()}
    thr = resolve_threshold(threshold, finals, config, reference)
    if budget is None:
        budget = max((run_generations(m) for runs in groups.values() for m in runs), default=0)
    methods = {k: summarize_method(runs, thr["value"], level, resamples) for k, runs in groups.items()}
    per_seed = {k: final_rewards(runs) for k, runs in groups.items()}
    poi = {x: {y: probability_of_improvement(per_seed[x], per_seed[y], level, resamples)
               for y in groups if y != x} for x in groups}
    # each method's censored generations and wall time to the threshold over each other's (the studies' ratios)
    costs = {k: m["to_threshold"] for k, m in methods.items()}
    ratios = {x: {y: {c: ratio_of_means(costs[x][c]["per_seed"], costs[y][c]["per_seed"], level, resamples)
                      for c in ("generations", "wall_time_s")} for y in groups if y != x} for x in groups}
    return clean_json({"ci_level": level, "threshold": thr, "budget_generations": budget,
                       "bootstrap": {"method": "percentile, each method's seeds resampled on their own",
                                     "resamples": resamples},
                       "methods": methods, "probability_of_improvement": poi, "ratios_to_threshold": ratios})


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
