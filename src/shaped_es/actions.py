"""The policy's outputs in ``[-1, 1]`` as actions of an env's action space, and back (:func:`from_space`, for a
scripted controller's recorded actions).

Every method's policy is one MLP with ``output_width(space)`` outputs in ``[-1, 1]``:

- ``Box(k)``: ``k`` outputs, rescaled to the bounds;
- ``Discrete(n)``: ``n`` outputs, the argmax;
- ``MultiDiscrete(nvec)`` (flat): ``sum(nvec)`` outputs, one argmax per sub-action over its own ``nvec[i]``;
- ``MultiBinary(n)`` (flat): ``n`` outputs, each bit 1 where its output is above 0.

A zero output is then the middle of a Box, and action 0 (the space's ``start``) of each choice: what "zero
action" means in the probe's and check-env's lines.
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

CHOICES = (gym.spaces.Discrete, gym.spaces.MultiDiscrete, gym.spaces.MultiBinary)  # spaces of argmax / sign outputs


def output_width(space: gym.Space) -> int | None:
    """The policy's output width for ``space`` (module docstring), or None where no policy here can act in it
    (a Box or multi-space of more than one axis, ``Tuple``, ``Dict``, ...)."""
    if isinstance(space, gym.spaces.Discrete):
        return int(space.n)
    if isinstance(space, (gym.spaces.Box, gym.spaces.MultiBinary)) and len(space.shape) == 1:
        return int(space.shape[0])
    if isinstance(space, gym.spaces.MultiDiscrete) and space.nvec.ndim == 1:
        return int(space.nvec.sum())
    return None


def flat_hint(space: gym.Space) -> str:
    """For a Box, MultiBinary or MultiDiscrete of other than one axis (a new user's ``Box(-1, 1, (2, 1))``), the
    way round the refusal: ``; declare it of shape (2,) and reshape inside step: ...``; ``""`` for other spaces."""
    shape = space.nvec.shape if isinstance(space, gym.spaces.MultiDiscrete) else getattr(space, "shape", None)
    if not isinstance(space, (gym.spaces.Box, gym.spaces.MultiBinary, gym.spaces.MultiDiscrete)) or len(shape) == 1:
        return ""
    return (f"; declare it of shape ({int(np.prod(shape))},) and reshape inside step: "
            f"action = np.reshape(action, {tuple(int(n) for n in shape)})")


def is_choice(space: gym.Space) -> bool:
    """Whether ``space``'s actions are choices (Discrete, MultiDiscrete, MultiBinary): a zero output is action 0."""
    return isinstance(space, CHOICES)


def _splits(space: gym.spaces.MultiDiscrete) -> np.ndarray:
    """Where each sub-action's outputs start in a MultiDiscrete policy output, past the first: ``(k - 1,)``."""
    return np.cumsum(space.nvec)[:-1]


def to_space(space: gym.Space, a: np.ndarray) -> np.ndarray:
    """Policy outputs ``(..., act)`` in ``[-1, 1]`` -> actions of ``space``: ``(...,)`` int64 for Discrete
    (the argmax), ``(..., k)`` int64 for MultiDiscrete (an argmax per sub-action), ``(..., n)`` int8 for
    MultiBinary (output > 0), ``(..., act)`` for Box, rescaled to its bounds as ``centre + half_width * a``,
    which is ``a`` itself, bit for bit, for the ``[-1, 1]`` Box of the built-in envs (whose batched cores take
    the policy's output as it is). Rollouts, ``load_policy(...).predict`` and ``render`` all map actions here."""
    if isinstance(space, gym.spaces.Discrete):
        return np.argmax(a, axis=-1).astype(np.int64) + int(space.start)
    if isinstance(space, gym.spaces.MultiDiscrete):
        parts = np.split(np.asarray(a), _splits(space), axis=-1)  # k arrays (..., nvec[i])
        return (np.stack([p.argmax(axis=-1) for p in parts], axis=-1) + space.start).astype(space.dtype)  # (..., k)
    if isinstance(space, gym.spaces.MultiBinary):
        return (np.asarray(a) > 0).astype(space.dtype)  # (..., n)
    low, high = space.low, space.high
    return ((high + low) * 0.5 + (high - low) * 0.5 * a).astype(space.dtype)


def from_space(space: gym.Space, a) -> np.ndarray:
    """One action of ``space`` -> the policy output ``(act,)`` float32 in ``[-1, 1]`` that maps to it (the inverse
    of :func:`to_space`, for a scripted controller's actions recorded as labels): Box rescaled from its bounds and
    clipped; a choice as +1 for the chosen option and -1 elsewhere (per sub-action for MultiDiscrete; MultiBinary:
    +1 for a set bit, -1 for a clear one)."""
    if isinstance(space, gym.spaces.Discrete):
        out = -np.ones(int(space.n), np.float32)
        out[int(a) - int(space.start)] = 1.0
        return out
    if isinstance(space, gym.spaces.MultiDiscrete):
        idx = np.asarray(a, np.int64).reshape(space.nvec.shape) - space.start  # (k,)
        out = -np.ones(int(space.nvec.sum()), np.float32)
        out[np.concatenate([[0], _splits(space)]) + idx] = 1.0
        return out
    if isinstance(space, gym.spaces.MultiBinary):
        return np.where(np.asarray(a).reshape(space.shape) > 0, 1.0, -1.0).astype(np.float32)
    low, high = space.low.astype(np.float64), space.high.astype(np.float64)
    x = 2.0 * (np.asarray(a, np.float64).reshape(low.shape) - low) / (high - low) - 1.0
    return np.clip(x, -1.0, 1.0).astype(np.float32)


def action_problem(space: gym.Space, a) -> str | None:
    """What makes ``a`` (a scripted controller's return) no action of ``space``, or None where it is one: the wrong
    number of values, a non-finite or non-integer value, a choice out of its range (``from_space`` would otherwise
    turn gear 3 of ``MultiDiscrete([3, 5])`` into another sub-action's +1 and train on it silently). A Box action
    beyond its bounds is one (clipped, as the rollouts clip the policy's)."""
    try:
        x = np.asarray(a, np.float64)
    except (TypeError, ValueError):
        return f"{type(a).__name__}, not numbers"
    want = 1 if isinstance(space, gym.spaces.Discrete) else int(np.prod(space.shape))
    if x.size != want:
        return f"{x.size} value{'s' if x.size != 1 else ''}, the space takes {want}"
    if not np.isfinite(x).all():
        return "a non-finite value"
    if not is_choice(space):
        return None
    if not np.array_equal(x, np.round(x)):
        return "a value that is not a whole number"
    if isinstance(space, gym.spaces.MultiBinary):
        return None if np.isin(x, (0, 1)).all() else "a value other than 0 or 1"
    low = np.ravel(np.asarray(space.start, np.float64))  # (k,) the first option of each choice
    high = low + (np.ravel(space.nvec) if isinstance(space, gym.spaces.MultiDiscrete) else int(space.n)) - 1
    out = np.flatnonzero((x.ravel() < low) | (x.ravel() > high))
    if out.size:
        i = int(out[0])
        where = f"sub-action {i}'s " if isinstance(space, gym.spaces.MultiDiscrete) else ""
        return f"{where}{x.ravel()[i]:g} is outside {int(low[i])}..{int(high[i])}"
    return None


def action_text(a) -> str:
    """A controller's return as its error lines quote it: one line, at most 60 characters (``[3 0]``, ``3``)."""
    return " ".join(str(a).split())[:60]


def zero_action(space: gym.Space):
    """The action of a zero policy output (the middle of a Box, action 0 of a choice), as ``env.step`` takes it."""
    return _to_env_action(space, np.zeros(output_width(space) or 0, np.float32))


def random_action(space: gym.Space, rng: np.random.Generator):
    """A uniformly random action of ``space`` drawn from ``rng`` (a choice, or a Box with finite bounds)."""
    if isinstance(space, gym.spaces.Discrete):
        return int(space.start + rng.integers(space.n))
    if isinstance(space, gym.spaces.MultiDiscrete):
        return (space.start + rng.integers(0, space.nvec)).astype(space.dtype)
    if isinstance(space, gym.spaces.MultiBinary):
        return rng.integers(0, 2, space.shape).astype(space.dtype)
    return to_space(space, rng.uniform(-1, 1, space.shape))


def _to_env_action(space: gym.Space, a: np.ndarray):
    """One policy output ``(act,)`` -> one action of ``space`` (:func:`to_space`; a Python int for Discrete)."""
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
