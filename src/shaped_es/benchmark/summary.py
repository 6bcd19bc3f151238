"""Across-seed summary of runs grouped by method (``summary.json`` of a benchmark).

Per method, over its seeds:

- ``final_test_reward_mean`` / ``final_test_reward_ci`` ([lo, hi], Student-t) and
  ``final_test_reward_iqm`` / ``final_test_reward_iqm_ci`` (interquartile mean, percentile-bootstrap
  interval; ``report/aggregate.py``) of each seed's last test evaluation (ES: the generation's best member
  over the test episodes; PPO: its deterministic policy);
- ``success_rate`` / ``successes``: the seeds whose test reward reached the threshold at some evaluation;
- ``to_threshold``: ``generations``, ``wall_time_s``, ``cpu_time_s``, ``env_steps`` at each seed's first
  evaluation with test reward >= threshold, **censored**: a seed that never reaches it counts as its own
  run's generations + 1 and as its whole run's wall time / CPU time / env steps (lower bounds), so
  the ``mean`` and ``median`` over all seeds are censored statistics (the median is exact while fewer
  than half the seeds are censored); ``per_seed`` and ``reached`` list each seed;
- ``wall_time_s``, ``cpu_time_s``, ``env_steps``, ``generations``: cost of a whole run, mean over seeds;
- ``time_split_s``: per-phase seconds (``gen_time_s``, ``rollout_time_s`` and every ``time_*_s``
  column) summed over a run's generations, mean over seeds.

Across methods: ``threshold`` (value and where it comes from: ``--threshold``, the env's default in
``DEFAULT_THRESHOLDS``, else the best baseline's final mean), ``budget_generations``, and
``probability_of_improvement[X][Y]``: P(final reward of a seed of X > one of Y) with a bootstrap
interval and the Mann-Whitney p-value.
"""

from __future__ import annotations

import json
import math
import re
import warnings
from pathlib import Path

import numpy as np

from shaped_es.config import RunConfig
from shaped_es.methods import METHODS
from shaped_es.report.aggregate import RESAMPLES, iqm_with_ci, probability_of_improvement
from shaped_es.report.plots import load_metrics
from shaped_es.report.seeds import copies_line, distinct_seeds
from shaped_es.report.stats import t_interval
from shaped_es.rundir.store import RunStore, StoreError

Metrics = dict[str, np.ndarray]
REFERENCE = "shaped"  # the paper's method: the fallback threshold is the best of the *other* methods
PHASE_COLUMN = re.compile(r"^(time_.+_s|gen_time_s|rollout_time_s)$")
COST_COLUMNS = ("wall_time_s", "cpu_time_s", "env_steps")
# Success thresholds of the built-in envs at their default reward scale (any preset or env setting that
# rescales the reward, e.g. preset=paper or max_steps, falls back to the best baseline's final mean):
# - CarNav-v0: +M/H per route waypoint, M = 250 over the whole route, -0.1 a step: 200 = the route
#   driven to (nearly) its end; stalling or crashing scores about -25 (docs/benchmarks/carnav).
# - UR5Reach-v0: +1 per Bezier waypoint (M = H = 100), -0.1 a step, -50 on a collision: 40 = half the
#   path followed without a collision (the hand-written follower scores 90, standing still about -4);
#   in docs/benchmarks/ur5 the final rewards of 3 seeds x 3 methods spread 9.6-61.9 and 7 of 9 end above it.
DEFAULT_THRESHOLDS = {
    "CarNav-v0": (200.0, "CarNav-v0 default: the route driven"),
    "UR5Reach-v0": (40.0, "UR5Reach-v0 default: half the Bezier path followed without a collision"),
}
REWARD_SCALE_KEYS = ("preset", "max_steps", "num_waypoints", "step_penalty", "collision_penalty")

class ReportWarning(UserWarning):
    """Runs of one method that ``group_runs`` reports apart (one line on the command line)."""


# fields of a method's sections that change no result (where shaping's arithmetic runs, where trajectory
# shards go, a diagnostic column): runs differing only in them stay one group
SAME_RESULTS = ("shaping.trajectory_root", "shaping.placement", "shaping.diagnose_returns")
LABEL_KEYS = 3  # differing settings named in a group's label at most (all of them in the warning)


def group_runs(run_dirs) -> tuple[dict[str, list[Path]], dict[str, RunConfig]]:
    """Run directories grouped by method (first-seen order), and one config per group (the first run's).
    A run of a benchmark (``DIR/runs/<name>_s<seed>``) is grouped by ``<name>``, so benchmark variants
    stay apart; any other run by the method in its ``config.yaml``. Runs of one group that differ in
    their env or in a setting of their method (:func:`run_settings`) are not pooled: each setting is a
    group of its own, labelled by what differs (``shaped (UR5Reach-v0)``, ``shaped
    (shaping.mechanism=subspace)``), with one :class:`ReportWarning` naming the differing keys. Within a
    group a seed counts once (``report/seeds.py``: a copied run, or one trained twice, is no second seed),
    with one :class:`ReportWarning` naming the copies left out."""
    found: dict[str, list[tuple[Path, RunConfig]]] = {}
    for d in run_dirs:
        store = RunStore(d)
        cfg = store.read_config()
        if not store.metrics_path.is_file():
            raise StoreError(f"{d} has no metrics.csv yet")
        m = re.fullmatch(r"(.+)_s\d+", Path(d).name)
        label = m.group(1) if m and Path(d).parent.name == "runs" else cfg.method
        found.setdefault(label, []).append((Path(d), cfg))
    groups: dict[str, list[Path]] = {}
    configs: dict[str, RunConfig] = {}
    for label, runs in found.items():
        for sub, members in _split(label, runs).items():
            members, copies = distinct_seeds(members, _seed, _length)
            if copies:
                warnings.warn(ReportWarning(copies_line(sub, _seed, copies)), stacklevel=2)
            groups[sub] = [d for d, _ in members]
            configs[sub] = members[0][1]
    return groups, configs


def _seed(run: tuple[Path, RunConfig]) -> int:
    return run[1].seed


def _length(run: tuple[Path, RunConfig]) -> int:
    return len(RunStore(run[0]).read_metrics())


def run_settings(cfg: RunConfig) -> dict:
    """What makes runs of one method different experiments: the env (its id, each ``env_kwargs`` entry)
    and the fields its method uses (the ``es`` fields it reads, ``rollout``, ``policy``, and ``shaping``
    or ``ppo`` if it reads them), flattened to ``section.field``. Not the seed, the budget, nor where and
    how a run ran (executor, workers, checkpoints, logging): they give the same numbers or a longer curve."""
    out: dict = {"env": cfg.env.removeprefix("shaped_es:")}
    out.update({f"env_kwargs.{k}": v for k, v in (cfg.env_kwargs or {}).items()})
    reads = METHODS[cfg.method].reads
    mine = cfg.model_dump(mode="json")
    for sec in ["es", "rollout", "policy"] + [s for s in ("shaping", "ppo") if s in reads]:
        out.update({k: v for k, v in _flat(mine[sec], f"{sec}.")
                    if k not in SAME_RESULTS and (sec != "es" or uses(cfg, k))})
    return out


def _split(label: str, runs: list[tuple[Path, RunConfig]]) -> dict[str, list[tuple[Path, RunConfig]]]:
    """``{label: runs}`` if the runs share their :func:`run_settings`, else one group per setting."""
    settings = [run_settings(cfg) for _, cfg in runs]
    keys = list(dict.fromkeys(k for s in settings for k in s))
    differ = [k for k in keys if len({_hashable(s.get(k, _UNSET)) for s in settings}) > 1]
    if not differ:
        return {label: runs}
    out: dict[str, list] = {}
    names: dict[tuple, str] = {}  # the differing values -> the group's label
    for run, s in zip(runs, settings):
        values = tuple(_hashable(s.get(k, _UNSET)) for k in differ)
        if values not in names:
            parts = [_describe(k, s.get(k, _UNSET)) for k in differ]
            if len(parts) > LABEL_KEYS:
                parts = parts[: LABEL_KEYS - 1] + [f"+{len(parts) - LABEL_KEYS + 1} more settings"]
            name = f"{label} ({', '.join(parts)})"
            while name in names.values():  # settings beyond the label's tell them apart
                name = f"{name} #{len(names) + 1}"
            names[values] = name
        out.setdefault(names[values], []).append(run)
    parts = "; ".join(f"{name} ({len(members)} run{'s' if len(members) > 1 else ''})"
                      for name, members in out.items())
    warnings.warn(ReportWarning(f"the {label!r} runs differ in {', '.join(differ)}, so they are reported "
                                f"apart, not averaged: {parts}"), stacklevel=3)
    return out


_UNSET = "(unset)"


def _describe(key: str, value) -> str:
    if key == "env":
        return str(value)
    return f"{key} unset" if value is _UNSET else f"{key}={plain(value)}"


def _hashable(v):
    return json.dumps(v, sort_keys=True, default=str) if isinstance(v, (list, dict)) else v


def _flat(d: dict, prefix: str):
    for k, v in d.items():
        yield from _flat(v, f"{prefix}{k}.") if isinstance(v, dict) else [(f"{prefix}{k}", v)]


def report_env(configs: dict[str, RunConfig]) -> tuple[str, RunConfig | None]:
    """The env the report names (its groups' envs, joined) and the config whose env gives the default
    success threshold (None when the groups' envs differ: no one env's threshold fits them all)."""
    envs = list(dict.fromkeys(c.env for c in configs.values()))
    scales = {json.dumps({"env": c.env.removeprefix("shaped_es:"), **(c.env_kwargs or {})}, sort_keys=True,
                         default=str) for c in configs.values()}
    first = next(iter(configs.values()), None)
    return ", ".join(envs), first if len(scales) == 1 else None


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


def run_generations(m: Metrics) -> int:
    g = m.get("generation")
    return int(np.nanmax(g)) + 1 if g is not None and np.isfinite(g).any() else 0


def summarize_method(runs: list[Metrics], threshold: float, level: float, resamples: int = RESAMPLES) -> dict:
    finals = final_rewards(runs)
    mean, half = t_interval(finals, level)
    robust = iqm_with_ci(finals, level, resamples)
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


def env_threshold(cfg: RunConfig | None) -> tuple[float, str] | None:
    """The env's default success threshold, if it has one at this config's reward scale."""
    if cfg is None:
        return None
    env = cfg.env.rsplit(":", 1)[-1]
    kwargs = cfg.env_kwargs or {}
    rescaled = [k for k in REWARD_SCALE_KEYS if k in kwargs and not (k == "preset" and kwargs[k] == "default")]
    return None if rescaled else builtin_threshold(env)


def builtin_threshold(env: str) -> tuple[float, str] | None:
    """A built-in env's success threshold at its default reward scale and where it comes from: the
    ``reward_threshold`` registered with its EnvSpec (``envs.BUILTIN``; its reason in the env module's
    docstring), CarNav-v0's and UR5Reach-v0's with their reasons here. None for any other env."""
    from shaped_es.envs import BUILTIN

    env = env.rsplit(":", 1)[-1]
    if env in DEFAULT_THRESHOLDS:
        return DEFAULT_THRESHOLDS[env]
    entry = BUILTIN.get(env)
    if entry is None or entry[2] is None:
        return None
    return float(entry[2]), f"{env} reward_threshold (registered; its reason in the env's docstring)"


def resolve_threshold(threshold: float | None, finals: dict[str, float], cfg: RunConfig | None = None,
                      reference: str = REFERENCE) -> dict:
    """{"value", "source", ...}: ``threshold`` if given, else the env's default, else the best baseline's
    final mean test reward (then also ``method`` and ``reference``)."""
    if threshold is not None:
        return {"value": float(threshold), "source": "--threshold"}
    default = env_threshold(cfg)
    if default is not None:
        return {"value": default[0], "source": default[1]}
    return {**pick_target(finals, reference), "source": "best baseline's final mean test reward"}


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
    return clean_json({"ci_level": level, "threshold": thr, "budget_generations": budget,
                       "bootstrap": {"method": "percentile, each method's seeds resampled on their own",
                                     "resamples": resamples},
                       "methods": methods, "probability_of_improvement": poi})


# the settings a reader needs to tell the runs apart, each shown for the methods that read it
KEY_SETTINGS = (("es.pairs", "pairs"), ("es.sigma", "sigma"), ("es.lr", "lr"), ("es.alpha", "alpha"),
                ("shaping.eta", "eta"))
SHOWN = {k for k, _ in KEY_SETTINGS} | {"rollout.episodes", "rollout.test_episodes"}


def uses(cfg: RunConfig, key: str) -> bool:
    """``cfg.method`` reads the config field ``key`` of a method-specific section (``Method.reads``)."""
    reads = METHODS[cfg.method].reads
    return key in reads or key.split(".")[0] in reads


def method_settings(cfg: RunConfig) -> dict:
    """The settings a reader needs to tell the runs apart, only those ``cfg.method`` uses (the fields it
    reads, ``Method.reads``; the executor only for ES methods: PPO runs in one process), as plain values."""
    out: dict = {"env": cfg.env}
    if cfg.env_kwargs:
        out["env_kwargs"] = ", ".join(f"{k}={v}" for k, v in cfg.env_kwargs.items())
    es = cfg.model_dump(mode="json")
    for key, name in KEY_SETTINGS:
        if uses(cfg, key):
            section, field = key.split(".")
            out[name] = es[section][field]
    out["episodes"], out["test episodes"] = cfg.rollout.episodes, cfg.rollout.test_episodes
    if METHODS[cfg.method].strategy is not None:  # ES: rollouts on the executor's workers
        out["executor"] = cfg.executor
        out["workers"] = cfg.workers if cfg.workers is not None else "all cores"
    else:
        out["executor"] = "none (one process)"
    out["other non-defaults"] = non_defaults(cfg)
    return out


def plain(v) -> str:
    """A setting as the report prints it: numbers with their significant digits, text as it is."""
    if isinstance(v, float):
        return f"{v:g}"
    return "none" if v is None else str(v)


def non_defaults(cfg: RunConfig) -> str:
    """``key=value`` of the fields that differ from the defaults among those ``cfg.method`` uses (what a
    benchmark ``--variant`` changed), besides the ones :func:`method_settings` names."""
    reads = METHODS[cfg.method].reads
    sections = ["es", "rollout", "policy"] + [s for s in ("shaping", "ppo") if s in reads]
    mine, base = cfg.model_dump(mode="json"), RunConfig().model_dump(mode="json")
    out = []
    for sec in sections:
        ref = dict(_flat(base[sec], f"{sec}."))
        out += [f"{k}={plain(v)}" for k, v in _flat(mine[sec], f"{sec}.")
                if k not in SHOWN and ref.get(k) != v and (sec != "es" or uses(cfg, k))]
    return "; ".join(out) or "none"


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
