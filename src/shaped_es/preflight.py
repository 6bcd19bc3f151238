"""Checks a run config can start, before anything is written to its run directory.

``train`` and ``benchmark`` call :func:`check_run` first, so bad input (an unknown env, spaces the
policy cannot use, ``--method shaped`` on an env without the waypoint contract or with a label source
that cannot serve (``shaping.labels=reference`` without a finished ``shaping.reference_run``,
``controller`` on an env without the hook), PPO without a time limit, strategy settings the strategy
refuses, a missing optional executor or wandb package, a policy or population that cannot fit in
memory, more local workers than a machine runs) fails with one line and leaves no directory that would
block the retry. Settings the method never reads (``shaping.*`` with vanilla) are one warning line.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

from shaped_es.config import ConfigError, RunConfig

if TYPE_CHECKING:
    from shaped_es.rollout import EnvProbe


def check_run(cfg: RunConfig, warn: bool = True) -> EnvProbe:
    """Raise ``ConfigError`` / ``EnvSpecError`` / ``ExecutorError`` (one line) if ``cfg`` cannot start;
    else the env probe the checks read (a train may take it: its env is not made again). ``warn``: say
    which settings the method ignores (:func:`warn_ignored`; a benchmark's settings are shared by its
    methods on purpose, so it does not)."""
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.methods import METHODS, resolve
    from shaped_es.rollout import probe_env

    if cfg.video_every is not None:  # before the env's module imports mujoco: its backend is read then
        from shaped_es.envs.gl import headless_gl

        headless_gl()
    # one env made for the dims, the time limit and (shaped) the reset info
    method = METHODS[cfg.method]
    probe = probe_env(cfg.env, cfg.env_kwargs, reset=method.probe_reset)
    if warn:
        warn_ignored(cfg)
    _check_executor(cfg.executor)
    _check_wandb(cfg)
    _check_workers(cfg)
    for check in method.checks:  # the method's own (methods.Method.checks)
        resolve(check)(cfg, probe)
    if cfg.video_every is not None:  # videos need rgb_array frames: refused here, before the run writes its config
        from shaped_es.trained.render import check_renders

        check_renders(cfg.env, cfg.env_kwargs)
    return probe


def check_es(cfg: RunConfig, probe: EnvProbe) -> None:
    """An ES method's checks: the policy and population fit in memory, the strategy takes its settings."""
    import numpy as np

    from shaped_es.methods import METHODS
    from shaped_es.rollout import policy_spec
    from shaped_es.trainer import build_strategy, check_obs_norm

    check_obs_norm(cfg)
    spec = policy_spec(cfg, probe)
    _check_memory(cfg, spec.num_params, METHODS[cfg.method].state_bytes(cfg, spec.num_params))
    try:
        build_strategy(cfg, np.zeros(spec.num_params))
    except ValueError as exc:
        if isinstance(exc, ConfigError):
            raise
        raise ConfigError(f"{cfg.method}: {str(exc).splitlines()[0]}") from None


def check_waypoints(cfg: RunConfig, probe: EnvProbe) -> None:
    """The waypoint contract of the probe's reset info (a method that reads it): ``info['position']`` and
    ``info['waypoint']`` finite arrays of one size (whether they are there at all: the method's own
    check, which says what it needs them for)."""
    from shaped_es.env_probe import BadOutput, waypoint_pair
    from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY
    from shaped_es.rollout import EnvSpecError

    info = probe.reset_info
    if isinstance(info, dict) and POSITION_KEY in info and WAYPOINT_KEY in info:
        try:
            waypoint_pair(info)
        except BadOutput as exc:
            raise EnvSpecError(f"env {cfg.env!r} returned {exc} from reset(seed=0)") from None


def warn_ignored(cfg: RunConfig) -> None:
    """One ``ConfigWarning`` line naming the settings changed from their defaults that ``cfg.method`` never
    reads (``Method.reads``: ``shaping.*`` with vanilla, ``ppo.*`` with an ES method, ``es.alpha`` with
    vanilla, ...), and which methods do read them."""
    import warnings

    from shaped_es.config import ConfigWarning
    from shaped_es.methods import METHODS

    def reads(method: str, key: str) -> bool:
        return any(key == r or key.startswith(r + ".") for r in METHODS[method].reads)

    values, defaults = cfg.model_dump(mode="json"), RunConfig().model_dump(mode="json")
    groups: dict[tuple[str, ...], list[str]] = {}  # methods that read them -> keys
    for section in ("es", "shaping", "ppo"):
        for key in _changed(values[section], defaults[section], f"{section}."):
            if not reads(cfg.method, key):
                groups.setdefault(tuple(m for m in METHODS if reads(m, key)), []).append(key)
    off = _overridden(cfg) if reads(cfg.method, "shaping") else []
    if off:
        warnings.warn("; ".join(off), ConfigWarning, stacklevel=2)
    if groups:
        parts = [f"{', '.join(keys)} (only --method {' / '.join(by)} {'uses' if len(by) == 1 else 'use'} "
                 f"{'it' if len(keys) == 1 else 'them'})" if by else ", ".join(keys) for by, keys in groups.items()]
        warnings.warn(f"--method {cfg.method} ignores {'; '.join(parts)}", ConfigWarning, stacklevel=2)


def _overridden(cfg: RunConfig) -> list[str]:
    """A sentence for each setting asked for that another setting turns off (a new user's ``rival_hold`` was
    dropped without a word where ``shoot_hold`` was on)."""
    mp = cfg.shaping.inverse_dynamics
    if not mp.rival_hold:
        return []
    if mp.shoot_hold:
        return ["shaping.inverse_dynamics.rival_hold is ignored: shoot_hold is on, so the shooting labels hold a goal "
                "already (the held-goal candidate would be theirs)"]
    if not mp.rival_shoot:
        return ["shaping.inverse_dynamics.rival_hold is ignored: rival_shoot is off, and the held-goal labels are the "
                "shooting labels' on their model"]
    return []


def _changed(values: dict, defaults: dict, prefix: str) -> list[str]:
    """Dotted keys under ``prefix`` whose value differs from the default (nested sections walked)."""
    out = []
    for k, v in values.items():
        if isinstance(v, dict) and isinstance(defaults.get(k), dict):
            out += _changed(v, defaults[k], f"{prefix}{k}.")
        elif v != defaults.get(k):
            out.append(f"{prefix}{k}")
    return out


def _physical_memory() -> int | None:
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):  # pragma: no cover - not POSIX
        return None


def _check_memory(cfg: RunConfig, n: int, state_bytes: int) -> None:
    """The population matrix (float32) and the strategy's state (``state_bytes``, ``Method.state_bytes``)
    must fit in half of this machine's RAM."""
    pop = 2 * cfg.es.pairs
    need = pop * n * 4 + state_bytes
    ram = _physical_memory()
    if ram and need > ram // 2:
        raise ConfigError(f"policy.hidden {list(cfg.policy.hidden)} gives {n:,} parameters; a population of "
                          f"{pop} needs {need / 2**30:,.1f} GiB, more than half of this machine's "
                          f"{ram / 2**30:,.1f} GiB: use a smaller policy.hidden or es.pairs")


def _check_workers(cfg: RunConfig) -> None:
    from shaped_es.executors.base import MAX_LOCAL_WORKERS, ExecutorError, usable_cores

    local = cfg.executor == "process" or (cfg.executor == "mpi" and not _under_mpiexec())
    if cfg.workers is not None and local and cfg.workers > MAX_LOCAL_WORKERS:
        raise ExecutorError(f"--workers {cfg.workers} is more than {MAX_LOCAL_WORKERS} local {cfg.executor} "
                            f"workers (this machine has {usable_cores()} cores); use --executor ray on a cluster")


def _under_mpiexec() -> bool:
    return any(v in os.environ for v in ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"))


def _check_executor(name: str) -> None:
    import importlib.util

    from shaped_es.executors import ExecutorError

    needs = {"ray": ("ray", "ray"), "mpi": ("mpi4py", "mpi")}.get(name)
    if needs and importlib.util.find_spec(needs[0]) is None:
        raise ExecutorError(f"{needs[0]} is not installed: pip install 'shaped-es[{needs[1]}]'")


def _check_wandb(cfg: RunConfig) -> None:
    import importlib.util

    if cfg.wandb.enabled and importlib.util.find_spec("wandb") is None:
        raise ConfigError("--wandb: the wandb package is not installed: pip install 'shaped-es[wandb]'")
