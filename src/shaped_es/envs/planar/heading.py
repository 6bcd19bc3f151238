"""What the planar bodies with a heading or first-order lags share (``unicycle.py``, ``rover.py``,
``kart.py``; the lag also ``pointforce.py``): the angle wrap, the step along the heading, the observation
with the goal in the body frame, a first-order lag and the input that closes one, and the speed that coasts
to the goal."""

from __future__ import annotations

import math

import numpy as np


def wrap(angle: np.ndarray) -> np.ndarray:
    """Angles wrapped to ``[-pi, pi)``."""
    return (angle + math.pi) % (2 * math.pi) - math.pi


def forward(pos: np.ndarray, heading: np.ndarray, dist: np.ndarray) -> np.ndarray:
    """``pos`` ``(B, 2)`` moved ``dist`` ``(B,)`` along ``heading`` ``(B,)`` (negative: backward)."""
    return pos + dist[:, None] * np.stack([np.cos(heading), np.sin(heading)], axis=1)


def heading_obs(state, *extra: np.ndarray) -> np.ndarray:
    """``(B, 6 + len(extra))`` float32: position (2), cos and sin of the heading (2), ``extra`` columns
    ``(B,)`` each, the goal - position in the body frame (2: ahead, left)."""
    c, s = np.cos(state.heading), np.sin(state.heading)  # (B,)
    d = state.goal - state.pos  # (B, 2)
    ahead, left = c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]  # body frame
    return np.stack([state.pos[:, 0], state.pos[:, 1], c, s, *extra, ahead, left], axis=1).astype(np.float32)


def lag(x: np.ndarray, u: np.ndarray, gain: float, damping: float, dt: float) -> np.ndarray:
    """One semi-implicit Euler step of ``x' = gain * u - damping * x``."""
    return x + dt * (gain * u - damping * x)


def lag_input(x: np.ndarray, target: np.ndarray, gain: float, damping: float, dt: float) -> np.ndarray:
    """The input (unclipped) that holds ``target`` against the damping and closes ``target - x`` in about
    two steps of :func:`lag`."""
    return (damping * target + (target - x) / (2 * dt)) / gain


def coast_speed(cfg, info: dict, share: np.ndarray) -> np.ndarray:
    """``share`` ``(B,)`` of the terminal speed ``accel / damping``, slower within the coasting distance of
    ``info["goal"]`` (``cfg``: a body config with ``accel`` and ``damping``)."""
    v_max = cfg.accel / cfg.damping
    goal_dist = np.linalg.norm(np.asarray(info["goal"]) - np.asarray(info["position"]), axis=1)
    brake = np.minimum(1.0, goal_dist * cfg.damping / v_max)
    return v_max * share * brake
