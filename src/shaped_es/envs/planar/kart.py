"""``Kart-v0``: a car-like body (kinematic bicycle) driven by acceleration and steering *rate* -- the pedal
changes the speed, the wheel's turning changes the steering angle, which sets the curvature: the heading
is third order in the steering input -- from a random start pose at rest to a random goal along spatial
waypoints (the shared task: ``task.py``; batched core: ``core.py``). Nonholonomic with a turning radius,
unlike Unicycle-v0 and Rover-v0, which turn on the spot.

Dynamics (semi-implicit Euler, ``dt`` = 0.1 s): ``v += dt * (accel * a[0] - damping * v)``, ``delta =
clip(delta + dt * steer_rate * a[1], -max_steer, max_steer)``, ``heading += dt * v * tan(delta) /
wheelbase``, ``p += dt * v * (cos heading, sin heading)``. Full pedal settles at ``accel / damping`` = 0.5
units/s (0.05 a step) with a time constant of 1 s; full lock (0.5 rad) is 0.25 s of full wheel-turning
away from straight, and turns on a circle of radius ``wheelbase / tan(max_steer)`` = 0.18. Negative speed
drives backward.

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: acceleration (+ = forward), steering rate (+ = to the left)
Observation        ``Box(-inf, inf, (8,))``: position (2), cos and sin of the heading (2), speed, steering
                   angle (2), goal - position in the body frame (2: ahead, left). No waypoints.
Reward             ``reward_progress`` 10 x the step's progress toward the goal / the start-goal distance +
                   ``reward_step`` -0.01
Episode            random start pose (at rest, wheels straight) and goal 0.5-1.5 apart; terminates within
                   0.05 of the goal; 120 steps
info               as PointVel-v0: ``position``, ``waypoint`` (every 0.1 on the line, consumed when reached
                   or passed), ``goal``, ``waypoint_index``, ``num_waypoints``, ``is_success``, reward terms
=================  ======================================================================================

Waypoint controller: pure pursuit -- the steering angle of the arc through a point ``LOOKAHEAD`` past the
waypoint toward the goal (full lock when it is behind; aiming at the waypoint itself circles it when it lies
inside the turning circle), reached by the wheel's rate within a step; the speed ``max(cos angle, 0.3)`` of
full (slower within the coasting distance of the goal), reached by the pedal.
Threshold (``reward_threshold`` 8.0): the controller scores 8.97 (mean of 200 episodes, min 8.32; every
episode at the goal within 88 steps); 8.0 leaves the margin Unicycle-v0 leaves below its controller.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shaped_es.envs.planar.core import PlanarCore, PlanarState
from shaped_es.envs.planar.env import PlanarEnv, config_maker, entry_points
from shaped_es.envs.planar.heading import coast_speed, forward, heading_obs, lag, lag_input, wrap
from shaped_es.envs.planar.task import PlanarTaskConfig

ENV_ID = "Kart-v0"
LOOKAHEAD = 0.3  # the controller's pure-pursuit lookahead past the waypoint (units)
REWARD_THRESHOLD = 8.0  # the controller's 8.97 (200 episodes, min 8.32) less a margin: the module docstring


@dataclass(frozen=True)
class KartConfig(PlanarTaskConfig):
    max_steps: int = 120  # it starts at rest with a turning circle: a goal behind takes a loop
    accel: float = 0.5  # pedal +-1 -> +- this acceleration (units / s^2)
    damping: float = 1.0  # viscous damping of the speed (1 / s)
    steer_rate: float = 2.0  # wheel +-1 -> +- this steering-angle rate (rad / s)
    max_steer: float = 0.5  # steering angle limit (rad)
    wheelbase: float = 0.1  # units

    def validate(self):
        if min(self.accel, self.damping, self.steer_rate, self.max_steer, self.wheelbase) <= 0:
            raise ValueError(f"{ENV_ID}: accel, damping, steer_rate, max_steer and wheelbase must be positive")
        if self.max_steer >= np.pi / 2:
            raise ValueError(f"{ENV_ID}: max_steer must be below pi/2")
        return super().validate()


PRESETS = {"default": KartConfig()}
make_config = config_maker(ENV_ID, PRESETS)


class KartCore(PlanarCore):
    """``state.vel`` holds (speed, steering angle), not a world velocity."""

    obs_dim = 8

    def move(self, state: PlanarState, act: np.ndarray):
        cfg = self.config
        v = lag(state.vel[:, 0], act[:, 0], cfg.accel, cfg.damping, cfg.dt)  # (B,)
        delta = np.clip(state.vel[:, 1] + cfg.dt * cfg.steer_rate * act[:, 1], -cfg.max_steer, cfg.max_steer)
        heading = wrap(state.heading + cfg.dt * v * np.tan(delta) / cfg.wheelbase)  # (B,)
        return forward(state.pos, heading, cfg.dt * v), np.stack([v, delta], axis=1), heading

    def observe(self, state: PlanarState) -> np.ndarray:
        return heading_obs(state, state.vel[:, 0], state.vel[:, 1])

    def waypoint_controller(self, state: PlanarState, obs: np.ndarray, info: dict) -> np.ndarray:
        """Pedal and wheel rate toward ``info["waypoint"]`` (pure pursuit, looking past it), ``(B, 2)``."""
        cfg = self.config
        pos, goal = np.asarray(info["position"]), np.asarray(info["goal"])  # (B, 2)
        # pure pursuit looks ahead: the point LOOKAHEAD past the waypoint toward the goal (at most the goal)
        w = np.asarray(info["waypoint"])
        ahead = goal - w  # (B, 2)
        n = np.linalg.norm(ahead, axis=1, keepdims=True)
        target = w + ahead * np.minimum(1.0, LOOKAHEAD / np.maximum(n, 1e-9))
        d = target - pos  # (B, 2)
        angle = wrap(np.arctan2(d[:, 1], d[:, 0]) - state.heading)  # (B,)
        dist = np.maximum(np.linalg.norm(d, axis=1), 1e-6)
        # the arc through the target has curvature 2 sin(angle) / dist; behind: full lock toward it
        curv = np.where(np.cos(angle) > 0, 2 * np.sin(angle) / dist, np.sign(angle) * 1e3)
        delta_des = np.clip(np.arctan(curv * cfg.wheelbase), -cfg.max_steer, cfg.max_steer)
        wheel = (delta_des - state.vel[:, 1]) / (cfg.dt * cfg.steer_rate)
        v_des = coast_speed(cfg, info, np.maximum(np.cos(angle), 0.3))
        pedal = lag_input(state.vel[:, 0], v_des, cfg.accel, cfg.damping, cfg.dt)
        return np.clip(np.stack([pedal, wheel], axis=1), -1.0, 1.0).astype(np.float32)


class KartEnv(PlanarEnv):
    env_id = ENV_ID
    core_cls = KartCore
    make_config = staticmethod(make_config)


make_limited, KartVectorEnv = entry_points(KartEnv)  # the registered entry points
