"""A scripted waypoint follower for CarNav-v0: pure pursuit of ``info["waypoint"]`` at a set speed.

It proves the task solvable (tests) and is the env's ``waypoint_controller`` hook (``envs/core.py``): the
``controller`` label source of ``--method shaped`` asks it what to do in every state a rollout visits. It
reads the car's yaw and speed from the core's state, which the policy never sees (paper, Sec. III).

Pure pursuit (Coulter 1992): with ``alpha`` the angle of the waypoint relative to the car's heading and
``l`` the look-ahead distance (the waypoint's distance, at least ``min_lookahead``), the front wheel angle
that puts the rear axle on an arc through the point is ``atan(2 L sin(alpha) / l)`` (``L`` the wheelbase);
throttle is proportional to the speed error, ``gain * (speed - v)``. Both are normalized and clipped to
``[-1, 1]`` like the policy's actions. At 6.5 m/s it scores ~226 on the default preset (the speed limit
is 6.9 m/s).
"""

from __future__ import annotations

import numpy as np

from shaped_es.envs.carnav.config import CarNavConfig


def pure_pursuit(config: CarNavConfig, yaw: np.ndarray, v: np.ndarray, position: np.ndarray,
                 waypoint: np.ndarray, speed: float = 6.5, min_lookahead: float = 2.5,
                 gain: float = 0.5) -> np.ndarray:
    """Actions ``(B, 2)`` (steer, throttle) in ``[-1, 1]`` for cars at ``position`` ``(B, 2)`` with
    ``yaw``, ``v`` ``(B,)`` heading for ``waypoint`` ``(B, 2)``."""
    d = np.asarray(waypoint, np.float64) - np.asarray(position, np.float64)  # (B, 2)
    alpha = np.angle(np.exp(1j * (np.arctan2(d[:, 1], d[:, 0]) - yaw)))  # (B,) wrapped to (-pi, pi]
    look = np.maximum(np.hypot(d[:, 0], d[:, 1]), min_lookahead)  # (B,)
    steer = np.arctan(config.wheelbase * 2.0 * np.sin(alpha) / look) / config.max_steer
    throttle = gain * (speed - np.asarray(v, np.float64))
    return np.clip(np.stack([steer, throttle], axis=1), -1.0, 1.0).astype(np.float32)  # (B, 2)
