"""A worker's envs, made once per env id and kwargs and kept across tasks, and the block that turns an
env's exception (or ``sys.exit``) into one :class:`~shaped_es.env_probe.EnvError` naming the env, the
generation and the episode seeds, dropping the envs it left in an unknown state.
"""

from __future__ import annotations

import contextlib
import json
import traceback

import gymnasium as gym
import numpy as np

from shaped_es.env_probe import EnvError, exception_line, make_env
from shaped_es.rollout.task import RolloutTask

_ENV_CACHE: dict[str, list[gym.Env]] = {}


def _env_key(env_id: str, env_kwargs: dict) -> str:
    return env_id + json.dumps(env_kwargs, sort_keys=True, default=str)


def _envs(env_id: str, env_kwargs: dict, count: int) -> list[gym.Env]:
    key = _env_key(env_id, env_kwargs)
    envs = _ENV_CACHE.setdefault(key, [])
    while len(envs) < count:
        envs.append(make_env(env_id, env_kwargs))
    return envs[:count]


@contextlib.contextmanager
def _env_faults(task: RolloutTask, seeds: np.ndarray):
    """An env's exception or ``sys.exit`` inside the block -> one :class:`EnvError` naming the env, the
    generation and the episode ``seeds``; the cached envs, in an unknown state, are dropped."""
    try:
        yield
    except Exception as exc:
        _ENV_CACHE.pop(_env_key(task.env_id, task.env_kwargs), None)  # envs in an unknown state
        if isinstance(exc, EnvError):
            raise
        raise EnvError(f"env {task.env_id!r} raised {exception_line(exc)} ({task.where()}, "
                       f"episode seeds {_seed_text(seeds)})", traceback.format_exc(),
                       worker_fault=bool(getattr(exc, "worker_fault", False))) from None
    except SystemExit as exc:  # would end the command (or the worker) as if the run had finished
        _ENV_CACHE.pop(_env_key(task.env_id, task.env_kwargs), None)
        raise EnvError(f"env {task.env_id!r} called sys.exit({exc.code!r}) during a rollout ("
                       f"{task.where()}, episode seeds {_seed_text(seeds)}); an env reports a failure "
                       f"by raising an exception", traceback.format_exc()) from None


def _seed_text(seeds: np.ndarray) -> str:
    flat = list(dict.fromkeys(int(x) for x in np.asarray(seeds).reshape(-1)))  # distinct, in order
    return ", ".join(map(str, flat[:3])) + (", ..." if len(flat) > 3 else "")
