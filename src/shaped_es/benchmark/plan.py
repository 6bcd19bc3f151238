"""What a rerun of a benchmark does with each run directory: ``new`` (none yet), ``restart`` (one without a
checkpoint) or ``reuse`` (:func:`plan_runs`), decided before any run starts.

Settings are compared per run, on the fields that run's method uses (:func:`method_digest`: ``ppo.*`` only
matter to PPO, ``shaping.*`` only to ``shaped``, ...), so a rerun with changed settings of one method reuses
every other method's runs, with this invocation's execution settings (generations, executor, workers, ...). A
run whose own settings changed is started afresh if it has no checkpoint yet; one with finished generations is
refused, before any run starts, in one line naming those runs (delete them to redo them with the new
settings). Reused runs made on an earlier version of the env's module are named in one warning line.
"""

from __future__ import annotations

import warnings
from pathlib import Path

from shaped_es.config import RunConfig, build_config
from shaped_es.methods import METHODS
from shaped_es.rundir.meta import RUNTIME_FIELDS
from shaped_es.rundir.store import RunStore, StoreError, StoreWarning


def _first_difference(a: RunConfig, b: RunConfig) -> str:
    da, db = _flat(_relevant(a)), _flat(_relevant(b))
    diff = sorted(k for k in set(da) | set(db) if da.get(k) != db.get(k))
    return ", ".join(diff[:3]) or "?"


def _flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        out.update(_flat(v, f"{prefix}{k}.") if isinstance(v, dict) and v else {f"{prefix}{k}": v})
    return out


# ``es`` fields a method never reads (trainer.build_strategy / build_guide, ppo_settings.horizon);
# anything not listed here counts, so a new field is compared until it is known to be irrelevant.
def _relevant(cfg: RunConfig) -> dict:
    """The config as JSON with the sections and ``es`` fields ``cfg.method`` never reads (``Method.reads``)
    reset to their defaults (``ppo`` reads only ``es.pairs``, for its env-step budget)."""
    d = cfg.model_dump(mode="json")
    defaults = RunConfig().model_dump(mode="json")
    reads = METHODS[cfg.method].reads
    for section in ("es", "shaping", "ppo"):
        if section not in reads:
            d[section] = {k: (v if f"{section}.{k}" in reads else defaults[section][k])
                          for k, v in d[section].items()}
    return d


def method_digest(cfg: RunConfig) -> str:
    """Hash of the settings that determine this run's results given its method."""
    from shaped_es.rundir.meta import config_digest

    return f"{cfg.method}:{config_digest(build_config(_relevant(cfg)))}"


def _reuse(old: RunConfig, new: RunConfig) -> RunConfig:
    """``old`` (the run's own config: its checkpoints were made with it) with this invocation's
    execution settings (generations, executor, workers, ...)."""
    d = old.model_dump(mode="json")
    nd = new.model_dump(mode="json")
    return build_config({**d, **{k: nd[k] for k in RUNTIME_FIELDS if k in nd}})


def plan_runs(cfgs: dict[str, RunConfig], runs_dir: Path) -> dict[str, tuple[str, RunConfig]]:
    """Per run: ``("new" | "restart" | "reuse", config to run with)``; refuses (``StoreError``, one line
    naming every such run) runs with finished generations whose own settings changed."""
    plan, changed, other_env = {}, [], []  # other_env: the envs of changed runs made on another env
    for name, cfg in cfgs.items():
        store = RunStore(runs_dir / name)
        if not store.exists():
            plan[name] = ("new", cfg)
            continue
        old = store.read_config()
        if old.method == cfg.method and method_digest(old) == method_digest(cfg):
            plan[name] = ("reuse", _reuse(old, cfg))
        elif not store.checkpoints():
            plan[name] = ("restart", cfg)  # nothing done yet (e.g. a run that failed to start)
        else:
            changed.append((name, _first_difference(old, cfg)))
            other_env += [old.env] if old.env != cfg.env else []
    if changed and len(other_env) == len(changed):  # a folder of another env's study, not changed settings
        envs = ", ".join(sorted(set(other_env)))
        env = next(iter(cfgs.values())).env
        raise StoreError(f"{runs_dir.parent} holds a benchmark of another env ({envs}), not {env}: a benchmark "
                         f"folder is one env's; use another --out")
    if changed:
        names = ", ".join(n for n, _ in changed)
        fields = ", ".join(sorted({f for _, d in changed for f in d.split(", ")})[:3])
        others = "the other runs are reused: " if plan else ""
        raise StoreError(f"runs {names} in {runs_dir} hold a different config ({fields}) with finished "
                         f"generations; {others}delete those to redo them with these settings, or use another "
                         f"--out")
    if cfgs:
        warn_env_edited(runs_dir, [n for n, (act, _) in plan.items() if act == "reuse"], next(iter(cfgs.values())).env)
    return plan


def warn_env_edited(runs_dir: Path, names: list[str], env_id: str) -> None:
    """One warning line naming the reused runs made on an earlier version of the env's module (its source hash
    in their ``run.json`` differs: ``rundir/env_source.py``): a rerun reuses them as they are."""
    from shaped_es.rundir.env_source import fingerprint

    now = fingerprint(env_id)  # hashed once, compared with each run's
    if now is None:
        return
    edited = [n for n in names if RunStore(runs_dir / n).env_changed(env_id, now)]
    if not edited:
        return
    file = Path(now["file"]).name
    shown = ", ".join(edited[:4]) + (f" and {len(edited) - 4} more" if len(edited) > 4 else "")
    warnings.warn(f"{file} changed since runs {shown} in {runs_dir} were made: they are reused as they are (their "
                  f"results are the earlier env's); delete them, or use another --out, to redo them on the env as "
                  f"it is now", StoreWarning, stacklevel=2)
