"""A worker's envs, made once per env id and kwargs and kept across tasks, and the block that turns an
env's exception (or ``sys.exit``) into one :class:`~shaped_es.env_probe.EnvError` naming the env, the
generation and the episode seed that raised (:func:`tag_seed`; the task's seeds where no one episode is
known), dropping the envs it left in an unknown state.
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
_SEED = "_shaped_es_episode_seed"  # on an env's exception: the seed of the episode that raised it


def _env_key(env_id: str, env_kwargs: dict) -> str:
    return env_id + json.dumps(env_kwargs, sort_keys=True, default=str)


def _envs(env_id: str, env_kwargs: dict, count: int) -> list[gym.Env]:
    key = _env_key(env_id, env_kwargs)
    envs = _ENV_CACHE.setdefault(key, [])
    while len(envs) < count:
        envs.append(make_env(env_id, env_kwargs))
    return envs[:count]


def tag_seed(exc: BaseException, seed) -> None:
    """Mark an env's exception ``exc`` with the ``seed`` of the episode whose reset or step raised it, for
    :func:`_env_faults`' line (a loop that steps its episodes one by one knows which one it was)."""
    if getattr(exc, _SEED, None) is None:
        with contextlib.suppress(AttributeError, TypeError):  # an exception type without a __dict__
            setattr(exc, _SEED, int(seed))


def drop_envs() -> None:
    """Close and forget this process's envs: the end of a command (``cli.commands.main``), whose episodes ran in its
    own process with ``inline``, so that a next command in that process (a script calling main() again) makes its
    own, as its workers' would be new: Gymnasium's env checker, which checks an env once, warns again into that
    run's error.log, and nothing an env holds (a simulator's connection) outlives the command."""
    while _ENV_CACHE:
        for env in _ENV_CACHE.popitem()[1]:
            with contextlib.suppress(Exception):  # the env's own close: the command's result stands
                env.close()


@contextlib.contextmanager
def _env_faults(task: RolloutTask, seeds: np.ndarray):
    """An env's exception or ``sys.exit`` inside the block -> one :class:`EnvError` naming the env, the
    generation and the episode seed that raised (:func:`tag_seed`), else the episode ``seeds`` of the block;
    the cached envs, in an unknown state, are dropped."""
    try:
        yield
    except Exception as exc:
        _ENV_CACHE.pop(_env_key(task.env_id, task.env_kwargs), None)  # envs in an unknown state
        if isinstance(exc, EnvError):
            raise
        raise EnvError(f"env {task.env_id!r} raised {exception_line(exc)} ({task.where()}, "
                       f"{_seed_text(exc, seeds)})", traceback.format_exc(),
                       worker_fault=bool(getattr(exc, "worker_fault", False))) from None
    except SystemExit as exc:  # would end the command (or the worker) as if the run had finished
        _ENV_CACHE.pop(_env_key(task.env_id, task.env_kwargs), None)
        raise EnvError(f"env {task.env_id!r} called sys.exit({exc.code!r}) during a rollout ("
                       f"{task.where()}, {_seed_text(exc, seeds)}); an env reports a failure "
                       f"by raising an exception", traceback.format_exc()) from None


def _seed_text(exc: BaseException, seeds: np.ndarray) -> str:
    """``episode seed S`` of the episode that raised ``exc``, or, where that is not known (a batched core steps
    every episode in one call), ``episode seeds ...`` of the block's ``seeds``."""
    seed = getattr(exc, _SEED, None)
    if seed is not None:
        return f"episode seed {seed}"
    flat = list(dict.fromkeys(int(x) for x in np.asarray(seeds).reshape(-1)))  # distinct, in order
    return "episode seeds " + ", ".join(map(str, flat[:3])) + (", ..." if len(flat) > 3 else "")
