"""What an ES run is built from: its method's strategy and guide (``methods.METHODS``), the check that the
method can use ``es.obs_norm``, its executor's options, and the line before a cold kernel compile.
"""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.config import ConfigError, RunConfig
from shaped_es.methods import METHODS, resolve
from shaped_es.policies import MLPSpec
from shaped_es.rollout import EnvProbe
from shaped_es.rundir.store import RunStore
from shaped_es.shaping.kernel_notice import say_if_compiling
from shaped_es.strategies import Strategy


def build_strategy(cfg: RunConfig, x0: np.ndarray) -> Strategy:
    """The strategy of ``cfg.method`` (its entry in :data:`methods.METHODS`) at ``x0`` ``(n,)``."""
    method = METHODS[cfg.method]
    if method.strategy is None:
        raise ValueError(f"method {cfg.method!r} is not an ES method (it has its own run loop)")
    seed = seeding.derive_seed(cfg.seed, seeding.STRATEGY)
    return resolve(method.strategy)(x0, **method.strategy_args(cfg, seed))


def check_obs_norm(cfg: RunConfig) -> None:
    """``ConfigError`` (one line) if ``es.obs_norm`` is set for a method that cannot use it yet
    (``methods.Method.no_obs_norm``)."""
    why = METHODS[cfg.method].no_obs_norm
    if cfg.es.obs_norm and why:
        raise ConfigError(f"es.obs_norm is not supported with --method {cfg.method} yet: {why}; "
                          f"set es.obs_norm=false")


def build_guide(cfg: RunConfig, spec: MLPSpec, store: RunStore, probe: EnvProbe | None = None, executor=None):
    """The guide of ``cfg.method`` (its entry in :data:`methods.METHODS`); ``probe``: the run's env probe;
    ``executor``: the run's (the shaped guide's label probe rolls out on its workers; None: in this process)."""
    method = METHODS[cfg.method]
    return resolve(method.guide)(**method.guide_args(cfg, spec, store, probe, executor))


def startup_notice(cfg: RunConfig, progress: bool, label: str) -> bool:
    """The line before a cold cache's kernel compile (``shaping/kernel_notice.py``), for the methods that
    use the kernels and not with ``--quiet``; returns whether it printed."""
    return bool(progress and METHODS[cfg.method].kernels and say_if_compiling(label))


def _executor_options(cfg: RunConfig) -> dict:
    opts: dict = {"max_retries": cfg.max_retries, "task_timeout_s": cfg.task_timeout_s}
    if cfg.executor == "ray":
        opts["address"] = cfg.address
    return {k: v for k, v in opts.items() if v is not None or k == "task_timeout_s"}
