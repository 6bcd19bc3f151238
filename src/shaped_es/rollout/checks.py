"""What an env returned during a rollout, checked: one :class:`~shaped_es.env_probe.EnvError` naming the
env, the generation, the episode seed and the step when an observation, a reward or the waypoint pair is
not what its spaces and the contract say.
"""

from __future__ import annotations

import numpy as np

from shaped_es.env_probe import BadOutput, EnvError, waypoint_pair
from shaped_es.rollout.task import RolloutTask


def _bad_output(task: RolloutTask, what: str, seed, step: int) -> EnvError:
    return EnvError(f"env {task.env_id!r} returned {what} ({task.where()}, episode seed "
                    f"{int(seed)}, step {step}); check the env's step/reset")


def _bad_controller(task: RolloutTask, what: str, seed, step: int) -> EnvError:
    """The env's scripted waypoint controller (the oracle labels, ``envs/core.py``) failed: ``what`` it did."""
    return EnvError(f"env {task.env_id!r}: its waypoint_controller {what} ({task.where()}, episode seed {int(seed)}, "
                    f"step {step}); it must return an action of the env's action space, as env.step takes it")


def _check_obs(task, obs: np.ndarray, shape: tuple, seed, step: int) -> np.ndarray:
    if obs.shape != shape:
        raise _bad_output(task, f"an observation of shape {obs.shape}, its observation space says {shape}",
                          seed, step)
    if not np.isfinite(obs).all():
        raise _bad_output(task, "a non-finite observation (inf/NaN)", seed, step)
    return obs


def _contract(task, info: dict, d: int | None, seed, step: int, finite: bool = True,
              dtype=np.float32) -> tuple[np.ndarray, np.ndarray]:
    """``info``'s position and waypoint (``env_probe.waypoint_pair``), or the error naming the env (``finite=False``:
    the caller checks the values are finite, :func:`_check_pairs`)."""
    try:
        return waypoint_pair(info, d, finite, dtype)
    except BadOutput as exc:
        raise _bad_output(task, str(exc), seed, step) from None


def _check_pairs(task, pos: np.ndarray, wp: np.ndarray, infos: list, seeds, step: int) -> None:
    """Every env's waypoint pair of this step ``(B, d)`` finite, or the first one's error (:func:`_contract`)."""
    if np.isfinite(pos).all() and np.isfinite(wp).all():
        return
    b = int(np.flatnonzero(~(np.isfinite(pos).all(axis=1) & np.isfinite(wp).all(axis=1)))[0])
    _contract(task, infos[b], pos.shape[1], seeds[b], step)
