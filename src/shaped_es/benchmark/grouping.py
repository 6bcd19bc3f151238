"""Which runs are one experiment, and the settings that tell runs apart (for ``report`` and a benchmark's
``summary.json`` / report page).

:func:`group_runs` groups run directories by method (a benchmark's runs by their variant's name), keeps
runs of one method that differ in their env or in a setting their method uses (:func:`run_settings`)
apart, and counts a seed once; :func:`method_settings` and :func:`non_defaults` are the settings a
reader needs, as plain values (:func:`plain`).
"""

from __future__ import annotations

import json
import re
import warnings
from pathlib import Path

from shaped_es.config import RunConfig
from shaped_es.methods import METHODS
from shaped_es.report.seeds import copies_line, distinct_seeds
from shaped_es.rundir.store import RunStore, StoreError


class ReportWarning(UserWarning):
    """Runs of one method that ``group_runs`` reports apart (one line on the command line)."""


# fields of a method's sections that change no result (where shaping's arithmetic runs, where trajectory
# shards go, a diagnostic column): runs differing only in them stay one group
SAME_RESULTS = ("shaping.trajectory_root", "shaping.placement", "shaping.diagnose_returns")
LABEL_KEYS = 3  # differing settings named in a group's label at most (all of them in the warning)


def split_run_name(name: str) -> tuple[str, int] | None:
    """``(method, seed)`` of a benchmark's run directory name ``METHOD_sSEED`` (``spec.run_name``); None for
    any other name."""
    m = re.fullmatch(r"(.+)_s(\d+)", name)
    return (m.group(1), int(m.group(2))) if m else None


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
        named = split_run_name(Path(d).name)
        label = named[0] if named and Path(d).parent.name == "runs" else cfg.method
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


# the settings a reader needs to tell the runs apart, each shown for the methods that read it
KEY_SETTINGS = (("es.pairs", "pairs"), ("es.sigma", "sigma"), ("es.lr", "lr"), ("es.alpha", "alpha"),
                ("shaping.eta", "eta"))
SHOWN = {k for k, _ in KEY_SETTINGS} | {"rollout.episodes", "rollout.test_episodes", "rollout.test_policy"}


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
        out["tested policy"] = cfg.rollout.test_policy
        out["executor"] = cfg.executor
        if cfg.executor != "inline":  # inline: the rollouts run in the trainer's process, no workers
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
