"""CarlaNav-v0's per-step terms, each CarNav-v0's rule: controls with the speed limit, waypoint
progress (``carnav/waypoints.py``'s kernels), reward terms and the observation (``carnav/observation.py``).

All inputs are plain numbers in the env's frame (``frame.py``), so every term is tested with exact
values without a server.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from shaped_es.envs.carla.frame import steer_command
from shaped_es.envs.carnav.config import NavTaskConfig
from shaped_es.envs.carnav.observation import obs_scales, state_obs
from shaped_es.envs.carnav.waypoints import advance, global_index, local_index


def control_values(steer: float, throttle: float, speed: float,
                   cfg: NavTaskConfig) -> tuple[float, float, float]:
    """``VehicleControl`` (steer, throttle, brake) for an action in [-1, 1]^2 at ``speed`` m/s.

    Steer +1 is full left (CarNav-v0), CARLA's -1. Throttle >= 0 opens the throttle, < 0 brakes (-1:
    full brake, CarNav-v0's ``max_brake``). Above ``speed_limit`` the throttle closes and the brake is
    at least ``auto_brake / max_brake`` (the paper's automatic braking; 1 with the defaults).
    """
    a = min(1.0, max(-1.0, float(throttle)))
    gas, brake = (a, 0.0) if a >= 0.0 else (0.0, -a)
    if speed > cfg.speed_limit:
        gas, brake = 0.0, max(brake, min(1.0, cfg.auto_brake / cfg.max_brake))
    return steer_command(steer), gas, brake


def reward_terms(reached: int, num_waypoints: int, collided: bool,
                 cfg: NavTaskConfig) -> tuple[float, float, float]:
    """(waypoint, step, collision) reward of a step: +M/H per waypoint reached, -0.1, -50 on a collision."""
    return (reached * cfg.max_steps / num_waypoints, -cfg.step_penalty,
            -cfg.collision_penalty if collided else 0.0)


@dataclass(frozen=True)
class CarState:
    """The ego vehicle in the env's frame: centre (m), yaw (rad), body velocities (m/s, lateral + left),
    yaw rate (rad/s, + counter-clockwise) and metres driven this episode."""

    x: float
    y: float
    yaw: float
    v_long: float
    v_lat: float
    yaw_rate: float
    odometer: float

    @property
    def speed(self) -> float:
        return math.hypot(self.v_long, self.v_lat)


class RouteProgress:
    """CarNav-v0's waypoint rules on one dense route ``(n, 2)``: the next global waypoint ``k``
    (1..H+1), the car's progress and the local waypoint (``carnav/waypoints.py``)."""

    def __init__(self, route: np.ndarray, cfg: NavTaskConfig):
        self.route = np.ascontiguousarray(route, dtype=np.float64)  # (n, 2)
        self.n = len(self.route)
        if self.n < 2:
            raise ValueError("a route needs at least 2 points")
        self.stride = cfg.wp_stride
        self.num_waypoints = (self.n - 2) // self.stride + 1  # H = ceil((n - 1) / stride), as CarNav-v0
        self.ahead = max(1, int(round(cfg.local_lookahead / cfg.dense_step)))
        self.reach, self.skip = cfg.reach_radius, cfg.skip_width
        self.k, self.progress, self.local, self.reached = 1, 0, 0, 0

    def move(self, x0: float, y0: float, x1: float, y1: float) -> int:
        """The car moved from (x0, y0) to (x1, y1): advance ``k``; returns the waypoints reached."""
        self.k, got = advance(x0, y0, x1, y1, self.route, self.n, self.stride, self.k, self.num_waypoints,
                              self.reach, self.skip)
        self.reached += got
        return int(got)

    def locate(self, x: float, y: float) -> None:
        """Update the car's progress and the local waypoint for the car at (x, y)."""
        g = self.goal_index()
        self.progress, self.local = local_index(x, y, self.route, self.n, self.progress, g, self.ahead)

    def goal_index(self) -> int:
        """Dense index of the next global waypoint (the last one once all are passed)."""
        return int(global_index(min(self.k, self.num_waypoints), self.stride, self.n))

    @property
    def done(self) -> bool:
        return self.k > self.num_waypoints

    def waypoint(self) -> np.ndarray:
        """The local waypoint ``(2,)`` (``info["waypoint"]``)."""
        return self.route[self.local].copy()


def observation(car: CarState, goal: np.ndarray, ranges: np.ndarray, cfg: NavTaskConfig) -> np.ndarray:
    """The 38-D observation ``(6 + beams,)`` float32 in CarNav-v0's layout and scales."""
    odo, v, w = obs_scales(cfg)
    out = np.empty(cfg.obs_dim, dtype=np.float32)
    state_obs(car.x, car.y, car.yaw, car.odometer, car.v_long, car.v_lat, car.yaw_rate, float(goal[0]),
              float(goal[1]), odo, v, w, out)
    out[6:] = np.clip(np.asarray(ranges, dtype=np.float64) / cfg.lidar_range, 0.0, 1.0)
    return out
