"""Waypoint positions that wrap around (a heading in (-pi, pi], an angle in degrees): the recorded steps and
queries of such a position taken the short way.

A wrapped angle reported as ``info['position']`` jumps by a full turn where the body crosses the cut: a one-step
displacement of ~2 pi among steps of ~0.01, and ``w_t - p_t`` the long way round on a quarter of a new user's
turntable's steps. M_phi trains on those rows as they are and its labels drove that body worse than zero action
(-125.6 against -113.5, where the same body reporting its unwrapped angle had labels at -20.4;
docs/benchmarks/heldout_turn_v23). Here a position is made continuous within each episode (each step's change
and the waypoint's offset taken modulo the period, into ``[-P/2, P/2)``), so every later difference -- a
displacement, ``w - p``, the motion frame -- is the body's real one.

Where the period comes from (:func:`period_of`, per env id and kwargs, once per process):

- the env declares it: ``env.unwrapped.position_period``, one number (every coordinate) or one per coordinate
  (``None`` or 0: that coordinate does not wrap); ``position_period = None`` turns detection off;
- else it is **detected** (:func:`detect`) from a few seeded random-action episodes of a fresh env (uniform, a
  corner held, a corner flipping to pump a swing): a coordinate
  wraps at 2 pi (or 360) if its values stay within one period, it jumps by about a period at least twice, and
  every other step is small. The same seeds in every process, so every worker and a resumed run find the same.
  Not for envs whose episodes run serially (a simulator server: declare it there) or with a batched core (the
  built-in envs, none of which wraps).

Hand-written: Gymnasium and NumPy have ``np.unwrap`` for one whole sequence, not a rollout's step-by-step state
over lock-step episodes with a waypoint beside it.
"""

from __future__ import annotations

import json
import math
from typing import NamedTuple

import gymnasium as gym
import numpy as np

from shaped_es.env_probe import EnvSpecError, close_env, make_env
from shaped_es.envs.core import POSITION_KEY, get_batch_core, runs_serially
from shaped_es.actions import random_action

PERIOD_ATTR = "position_period"  # env.unwrapped.position_period: a number, one per coordinate, or None
PERIODS = (2 * math.pi, 360.0)  # what detection recognizes: radians, degrees
# a third each: uniform random actions; one random corner of the action space held; a corner whose sign flips
# every 5-40 steps (it pumps a swing: a new user's pendulum whose cut is at the top crossed it only so)
DETECT_EPISODES = 12
DETECT_STEPS = 200  # at most this many steps of each (an env without a time limit, a long one)
_UNSET = object()
_CACHE: dict[str, np.ndarray | None] = {}
_DECLARATIONS: dict[str, Declaration] = {}  # env id, kwargs and d -> what the env says (:func:`declaration`)


def wrap(x: np.ndarray, period: np.ndarray) -> np.ndarray:
    """``x`` ``(..., d)`` with each periodic coordinate (``period > 0``) taken into ``[-P/2, P/2)``; the others as
    they are. float64."""
    x = np.asarray(x, np.float64)
    p = np.asarray(period, np.float64)
    on = p > 0
    safe = np.where(on, p, 1.0)
    return np.where(on, x - safe * np.floor(x / safe + 0.5), x)


class Unwrapper:
    """Continuous positions and their waypoints ``(B, d)`` for ``B`` lock-step episodes of a periodic position:
    :meth:`start` at reset, :meth:`step` for each episode that stepped. float64."""

    def __init__(self, period: np.ndarray):
        self.period = np.asarray(period, np.float64)  # (d,)
        self.raw = None  # (B, d) the env's last reported positions
        self.pos = None  # (B, d) the continuous positions

    def start(self, raw_pos: np.ndarray, raw_wp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self.raw = np.array(raw_pos, np.float64)  # (B, d)
        self.pos = self.raw.copy()
        return self.pos.copy(), self.pos + wrap(np.asarray(raw_wp, np.float64) - self.raw, self.period)

    def step(self, b: int, raw_pos: np.ndarray, raw_wp: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Episode ``b``'s new ``(d,)`` position and waypoint: the last position plus the step the short way, the
        waypoint at its short-way offset from it."""
        raw_pos = np.asarray(raw_pos, np.float64)
        self.pos[b] = self.pos[b] + wrap(raw_pos - self.raw[b], self.period)
        self.raw[b] = raw_pos
        return self.pos[b].copy(), self.pos[b] + wrap(np.asarray(raw_wp, np.float64) - raw_pos, self.period)


def declared(env: gym.Env, d: int):
    """The env's own ``position_period`` as ``(d,)`` float64 (0: not periodic), ``None`` where it declares
    ``None`` (no wrap, no detection), or ``_UNSET`` where it has no such attribute. A bad value is one
    :class:`EnvSpecError` line."""
    v = getattr(getattr(env, "unwrapped", env), PERIOD_ATTR, _UNSET)
    if v is _UNSET or v is None:
        return v
    many = isinstance(v, (list, tuple, np.ndarray))
    try:
        vals = [0.0 if x is None else float(x) for x in (v if many else [v] * d)]
    except (TypeError, ValueError):
        vals = None
    wrong = ("not a number" if vals is None else f"{len(vals)} periods for {d} coordinates" if len(vals) != d
             else "a period that is negative or not finite" if not all(math.isfinite(x) and x >= 0 for x in vals)
             else "")
    if wrong:
        raise EnvSpecError(f"{PERIOD_ATTR} = {v!r} ({wrong}): give one period (a positive number) for all "
                           f"coordinates of info['{POSITION_KEY}'], a list of {d} (one per coordinate; None or 0 "
                           "where it does not wrap), or None (nothing wraps)")
    out = np.array(vals, np.float64)
    return out if (out > 0).any() else None


def detect(episodes: list[np.ndarray]) -> np.ndarray | None:
    """The period ``(d,)`` (0: not periodic) of positions recorded over ``episodes`` (each ``(T, d)``), or None
    where no coordinate wraps. A coordinate wraps at ``P`` (2 pi or 360) if all its values lie within ``1.02 P``
    of each other, it jumps by ``0.75-1.25 P`` at least twice, every other step is below ``P / 8`` and the median
    step below ``P / 20``: a body that moves continuously does none of these; a teleport by another amount, a
    large step, or values spread wider than a turn each rule it out."""
    eps = [np.asarray(e, np.float64).reshape(len(e), -1) for e in episodes if len(e) > 1]
    if not eps:
        return None
    return _wraps(np.concatenate(eps), np.abs(np.concatenate([np.diff(e, axis=0) for e in eps])))


def detect_recorded(position: np.ndarray, follows: np.ndarray) -> np.ndarray | None:
    """:func:`detect` on recorded rows ``(N, d)`` (a generation's), ``follows`` ``(N,)`` True where row ``t + 1``
    continues row ``t``'s episode (``Transitions.next_position``'s mask): a wrap the start's random-action episodes
    did not show. Rows already unwrapped do not wrap."""
    pos = np.asarray(position, np.float64)
    cont = np.asarray(follows, bool)[:-1]  # (N - 1,) row i + 1 is row i's next step
    if not cont.any():
        return None
    paired = np.zeros(len(pos), bool)  # (N,) rows of an episode with a step (detect's episodes of 2+ rows)
    paired[:-1] |= cont
    paired[1:] |= cont
    return _wraps(pos[paired], np.abs(np.diff(pos, axis=0))[cont])


def _wraps(vals: np.ndarray, steps: np.ndarray) -> np.ndarray | None:
    """:func:`detect`'s rule on the positions ``(N, d)`` and the absolute steps ``(M, d)`` within episodes."""
    out = np.zeros(vals.shape[1])
    for k in range(vals.shape[1]):
        span = vals[:, k].max() - vals[:, k].min()
        for P in PERIODS:
            s = steps[:, k]
            jump = (s > 0.75 * P) & (s < 1.25 * P)
            rest = s[~jump]
            if (span <= 1.02 * P and jump.sum() >= 2 and rest.size and rest.max() < P / 8
                    and np.median(rest) < P / 20):
                out[k] = P
                break
    return out if (out > 0).any() else None


def _action(space: gym.Space, rng: np.random.Generator, corner: np.ndarray | None):
    """A random action of ``space``: uniform (``corner`` None) or the given corner (signs ``(act,)``) of a Box."""
    if not isinstance(space, gym.spaces.Box):
        return random_action(space, rng)
    low, high = np.asarray(space.low, np.float64), np.asarray(space.high, np.float64)
    a = rng.uniform(-1, 1, space.shape) if corner is None else corner
    bounded = np.isfinite(low) & np.isfinite(high)
    return np.where(bounded, (high + low) * 0.5 + (high - low) * 0.5 * a, a).astype(space.dtype)


def detect_env(env_id: str, env_kwargs: dict) -> np.ndarray | None:
    """:func:`detect` on ``DETECT_EPISODES`` seeded random-action episodes of a fresh env (None if it fails: the
    rollout that follows reports the env's own error)."""
    rng = np.random.default_rng(20_261_206)
    env = make_env(env_id, env_kwargs)
    try:
        episodes = []
        for e in range(DETECT_EPISODES):
            _, info = env.reset(seed=int(rng.integers(2**31 - 1)))
            space = env.action_space
            corner, flip = None, 0
            if e % 3 and isinstance(space, gym.spaces.Box):
                corner = rng.choice([-1.0, 1.0], size=space.shape)
                flip = int(rng.integers(5, 41)) if e % 3 == 2 else 0
            pos = [np.asarray(info[POSITION_KEY], np.float64).reshape(-1)]
            for t in range(DETECT_STEPS):
                if flip and t and t % flip == 0:
                    corner = -corner
                _, _, term, trunc, info = env.step(_action(space, rng, corner))
                pos.append(np.asarray(info[POSITION_KEY], np.float64).reshape(-1))
                if term or trunc:
                    break
            episodes.append(np.stack(pos))  # (T, d)
        return detect(episodes)
    except Exception:  # noqa: BLE001 - the env's own failure: the rollout itself reports it, in its words
        return None
    finally:
        try:
            env.close()
        except Exception:  # noqa: BLE001
            pass


class Declaration(NamedTuple):
    """What an env says of its period (:func:`declaration`)."""

    declares: bool  # it has a position_period (even None)
    period: np.ndarray | None  # :func:`declared`'s (d,) where it declares one (None: it does not, or declares None)
    detectable: bool  # :func:`detectable`


def declaration(env_id: str, env_kwargs: dict, d: int, env: gym.Env | None = None) -> Declaration:
    """What the env declares, read from ``env`` or from one env made here; once per env id, kwargs and ``d`` in a
    process, so a shaped run's preflight (``check_period``) and its guide's line (``wrap_line``) make one env for
    it, not two. A bad declaration raises (:func:`declared`), each time."""
    key = f"{_key(env_id, env_kwargs)}/{d}"
    if key not in _DECLARATIONS:
        made = env is None
        env = make_env(env_id, env_kwargs) if made else env
        try:
            own = declared(env, d)
            _DECLARATIONS[key] = Declaration(own is not _UNSET, None if own is _UNSET else own, detectable(env))
        finally:
            if made:
                close_env(env, env_id)
    return _DECLARATIONS[key]


def period_of(env: gym.Env | None, env_id: str, env_kwargs: dict, d: int) -> np.ndarray | None:
    """The period ``(d,)`` of ``env``'s ``info['position']`` (0: not periodic), or None where nothing wraps:
    declared, else detected (module docstring); once per env id and kwargs in a process (``env`` None: what
    :func:`declaration` has, or one env made for it)."""
    key = _key(env_id, env_kwargs)
    if key not in _CACHE:
        said = declaration(env_id, env_kwargs, d, env)
        _CACHE[key] = said.period if said.declares else (detect_env(env_id, env_kwargs) if said.detectable
                                                         else None)
    per = _CACHE[key]
    return None if per is None or per.shape != (d,) else per


def _key(env_id: str, env_kwargs: dict) -> str:
    """The caches' key of an env id and its kwargs."""
    return env_id + json.dumps(env_kwargs, sort_keys=True, default=str)


def describe(period: np.ndarray | None, detected: bool, how: str | None = None) -> str:
    """``info['position'] wraps ([0] at 2 pi; detected from random-action episodes)``, ``""`` where nothing wraps
    (``how``: another source than ``detected``'s)."""
    if period is None:
        return ""
    how = how or ("detected from random-action episodes" if detected else f"the env's {PERIOD_ATTR}")
    return f"info['{POSITION_KEY}'] wraps ({coords_text(period)}; {how})"


def wrap_text(period: np.ndarray | None, declared: bool) -> str:
    """``info['position'] wraps ([0] at 2 pi; detected ...): shaped runs record it continuous ...``: the one line
    check-env and a shaped run's start give a position that wraps, with the hint to declare it where it was
    detected; ``""`` where nothing wraps."""
    if period is None:
        return ""
    hint = "" if declared else f" (declare env.unwrapped.{PERIOD_ATTR} to say so yourself, None if it does not wrap)"
    return (f"{describe(period, not declared)}: shaped runs record it continuous and take each step and w - p the "
            f"short way{hint}")


def coords_text(period: np.ndarray) -> str:
    """``[0] at 2 pi, [1] at 360``: the coordinates that wrap and their periods."""
    return ", ".join(f"[{k}] at {'2 pi' if abs(p - 2 * math.pi) < 1e-9 else f'{p:g}'}"
                     for k, p in enumerate(period) if p > 0)


def detectable(env: gym.Env) -> bool:
    """Detection may run a fresh copy of ``env`` (not a batched core's, not a simulator's run serially)."""
    return get_batch_core(env) is None and not runs_serially(env)


def is_declared(env: gym.Env) -> bool:
    """True if the env says itself whether its position wraps (``position_period``, even None)."""
    return getattr(getattr(env, "unwrapped", env), PERIOD_ATTR, _UNSET) is not _UNSET


__all__ = ["PERIOD_ATTR", "Declaration", "Unwrapper", "coords_text", "declaration", "declared", "describe", "detect",
           "detect_env", "detect_recorded", "detectable", "is_declared", "period_of", "wrap", "wrap_text"]
