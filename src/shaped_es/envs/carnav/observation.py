"""The first six observation terms of the driving task and their scales, shared by CarNav-v0's kernel
(``core.py``) and CarlaNav-v0 (``envs/carla``), so the same index means the same quantity on both.

Frame: right-handed, x east, y north, yaw counter-clockwise from +x (radians); body velocities are
forward and lateral (+ left), the yaw rate is + counter-clockwise. Scales (:func:`obs_scales`):
odometry 1 = the distance driven at the speed limit over a whole episode (``speed_limit * dt * M``),
velocities 1 = the speed limit, yaw rate 1 = the yaw rate at full lock and the speed limit of the
kinematic bicycle of ``vehicle.py`` (``l_r``, ``L`` and ``max_steer`` of the config).
"""

from __future__ import annotations

import math

import numba as nb


def obs_scales(cfg) -> tuple[float, float, float]:
    """(odometry, velocity, yaw-rate) scales of a :class:`~shaped_es.envs.carnav.config.NavTaskConfig`."""
    beta_max = math.atan(cfg.rear_to_center / cfg.wheelbase * math.tan(cfg.max_steer))
    odo = 1.0 / (cfg.speed_limit * cfg.dt * cfg.max_steps)  # 1: at the limit all episode
    return odo, 1.0 / cfg.speed_limit, cfg.rear_to_center / (cfg.speed_limit * math.sin(beta_max))


@nb.njit(cache=True, inline="always")
def state_obs(x, y, yaw, odometer, v_long, v_lat, yaw_rate, gx, gy, odo_scale, v_scale, w_scale, out):
    """Write observation terms 0-5 into ``out``: sin and cos of the heading error to the next global
    waypoint ``(gx, gy)``, odometry, forward and lateral velocity, yaw rate (each clipped to [-1, 1])."""
    dx, dy = gx - x, gy - y
    d = math.hypot(dx, dy)
    ch, sh = math.cos(yaw), math.sin(yaw)
    out[0] = (ch * dy - sh * dx) / d if d > 1e-9 else 0.0  # sin(heading error)
    out[1] = (ch * dx + sh * dy) / d if d > 1e-9 else 1.0  # cos(heading error)
    out[2] = min(odometer * odo_scale, 1.0)
    out[3] = max(-1.0, min(1.0, v_long * v_scale))
    out[4] = max(-1.0, min(1.0, v_lat * v_scale))
    out[5] = max(-1.0, min(1.0, yaw_rate * w_scale))
