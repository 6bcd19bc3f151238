"""Checks a run config can start, before anything is written to its run directory.

``train`` and ``benchmark`` call :func:`check_run` first, so bad input (an unknown env, spaces the
policy cannot use, ``--method shaped`` on an env without the waypoint contract, PPO without a time
limit, strategy settings the strategy refuses, a missing optional executor) fails with one line and
leaves no directory that would block the retry.
"""

from __future__ import annotations

from shaped_es.config import ConfigError, RunConfig


def check_run(cfg: RunConfig) -> None:
    """Raise ``ConfigError`` / ``EnvSpecError`` / ``ExecutorError`` (one line) if ``cfg`` cannot start."""
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.rollout import env_dims, make_env

    env = make_env(cfg.env, cfg.env_kwargs)
    try:
        obs_dim, act_dim = env_dims(env)
    finally:
        env.close()
    _check_executor(cfg.executor)
    if cfg.method == "ppo":
        from shaped_es.baselines.ppo import env_time_limit
        from shaped_es.baselines.ppo_settings import iterations_per_generation, ppo_settings

        iterations_per_generation(cfg, ppo_settings(cfg), env_time_limit(cfg))  # e.g. no time limit
        return
    import numpy as np

    from shaped_es.policies import MLPSpec
    from shaped_es.trainer import build_strategy

    spec = MLPSpec(obs_dim, act_dim, tuple(cfg.policy.hidden))
    try:
        build_strategy(cfg, np.zeros(spec.num_params))
    except ValueError as exc:
        if isinstance(exc, ConfigError):
            raise
        raise ConfigError(f"{cfg.method}: {str(exc).splitlines()[0]}") from None
    if cfg.method == "shaped":
        from shaped_es.guides.shaped import waypoint_dim

        waypoint_dim(cfg)  # the env contract: info['position'] and info['waypoint']


def _check_executor(name: str) -> None:
    import importlib.util

    from shaped_es.executors import ExecutorError

    needs = {"ray": ("ray", "ray"), "mpi": ("mpi4py", "mpi")}.get(name)
    if needs and importlib.util.find_spec(needs[0]) is None:
        raise ExecutorError(f"{needs[0]} is not installed: pip install 'shaped-es[{needs[1]}]'")
