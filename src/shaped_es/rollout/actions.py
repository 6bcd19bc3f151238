"""The policy's outputs in ``[-1, 1]`` as actions of an env's action space (the inverse, for recorded
controller actions, is ``record._from_env_action``).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np


def to_space(space: gym.Space, a: np.ndarray) -> np.ndarray:
    """Policy outputs ``(..., act)`` in ``[-1, 1]`` -> actions of ``space``: ``(...,)`` int64 for Discrete
    (the argmax), ``(..., act)`` for Box, rescaled to its bounds as ``centre + half_width * a``, which is
    ``a`` itself, bit for bit, for the ``[-1, 1]`` Box of the built-in envs (whose batched cores take the
    policy's output as it is). Rollouts, ``load_policy(...).predict`` and ``render`` all map actions here."""
    if isinstance(space, gym.spaces.Discrete):
        return np.argmax(a, axis=-1).astype(np.int64) + int(space.start)
    low, high = space.low, space.high
    return ((high + low) * 0.5 + (high - low) * 0.5 * a).astype(space.dtype)


def _to_env_action(space: gym.Space, a: np.ndarray):
    """One policy output ``(act,)`` -> one action of ``space`` (:func:`to_space`)."""
    out = to_space(space, a)
    return int(out) if isinstance(space, gym.spaces.Discrete) else out


def action_map(space: gym.Space):
    """:func:`_to_env_action` for one space, its bounds' arithmetic done once: a rollout maps an action per env
    step (``centre + half * a`` evaluates as :func:`to_space`'s ``(high + low) * 0.5 + (high - low) * 0.5 * a``, bit
    for bit; 1-2 us a step instead of 6-8, hand-written since Gymnasium's wrappers re-derive them each call)."""
    if not isinstance(space, gym.spaces.Box):
        return lambda a: _to_env_action(space, a)
    centre, half, dtype = (space.high + space.low) * 0.5, (space.high - space.low) * 0.5, space.dtype
    return lambda a: (centre + half * a).astype(dtype)
