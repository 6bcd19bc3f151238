"""``Rover-v0``: a differential-drive body with inertia -- thrust and yaw torque, not speed and turn rate
(second order in both: the action changes the forward speed and the yaw rate, which then move the body),
from a random start pose at rest to a random goal along spatial waypoints (the shared task: ``task.py``;
batched core: ``core.py``). Unicycle-v0 one order up: the kind of tractor, boat or skid-steer robot whose
one-step displacement hardly depends on this step's action.

Dynamics (semi-implicit Euler, ``dt`` = 0.1 s): ``v += dt * (accel * a[0] - damping * v)``, ``w += dt *
(yaw_accel * a[1] - yaw_damping * w)``, ``heading += dt * w``, ``p += dt * v * (cos heading, sin heading)``.
Full thrust settles at ``accel / damping`` = 0.5 units/s (0.05 a step, Unicycle-v0's speed) with a time
constant of 1 s (10 steps); full torque at ``yaw_accel / yaw_damping`` = 5 rad/s (0.5 rad a step, the
unicycle's turn rate) with a time constant of 0.5 s (5 steps).

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: thrust (+ = forward), yaw torque (+ = counter-clockwise)
Observation        ``Box(-inf, inf, (8,))``: position (2), cos and sin of the heading (2), forward speed,
                   yaw rate (2), goal - position in the body frame (2: ahead, left). No waypoints.
Reward             ``reward_progress`` 10 x the step's progress toward the goal / the start-goal distance +
                   ``reward_step`` -0.01
Episode            random start pose (at rest) and goal 0.5-1.5 apart; terminates within 0.05 of the goal;
                   120 steps
info               as PointVel-v0: ``position``, ``waypoint`` (every 0.1 on the line, consumed when reached
                   or passed), ``goal``, ``waypoint_index``, ``num_waypoints``, ``is_success``, reward terms
=================  ======================================================================================

Waypoint controller: a cascade -- the yaw rate that turns toward the waypoint (``gain_turn x angle``,
clipped to the terminal yaw rate), the speed ``max(cos angle, 0)`` of full (slower within braking distance),
each reached by the torque or thrust that closes its error (plus the damping's share) within a step or two.
Threshold (``reward_threshold`` 8.0): the controller scores 9.07 (mean of 200 episodes, min 8.72); 8.0 leaves
the margin Unicycle-v0 leaves below its controller (about 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shaped_es.envs.planar.core import PlanarCore, PlanarState
from shaped_es.envs.planar.env import PlanarEnv, config_maker, entry_points
from shaped_es.envs.planar.heading import coast_speed, forward, heading_obs, lag, lag_input, wrap
from shaped_es.envs.planar.task import PlanarTaskConfig

ENV_ID = "Rover-v0"
REWARD_THRESHOLD = 8.0  # the controller scores 9.07 (200 episodes, min 8.72) less a margin, as Unicycle-v0


@dataclass(frozen=True)
class RoverConfig(PlanarTaskConfig):
    max_steps: int = 120  # it starts at rest: speeding up takes ~10 steps, a half turn ~10
    accel: float = 0.5  # thrust +-1 -> +- this forward acceleration (units / s^2)
    damping: float = 1.0  # forward viscous damping (1 / s)
    yaw_accel: float = 10.0  # torque +-1 -> +- this yaw acceleration (rad / s^2)
    yaw_damping: float = 2.0  # yaw damping (1 / s)

    def validate(self):
        if min(self.accel, self.yaw_accel, self.damping, self.yaw_damping) <= 0:
            raise ValueError(f"{ENV_ID}: accel, yaw_accel, damping and yaw_damping must be positive")
        return super().validate()


PRESETS = {"default": RoverConfig()}
make_config = config_maker(ENV_ID, PRESETS)


class RoverCore(PlanarCore):
    """``state.vel`` holds (forward speed, yaw rate), not a world velocity."""

    obs_dim = 8

    def move(self, state: PlanarState, act: np.ndarray):
        cfg = self.config
        v = lag(state.vel[:, 0], act[:, 0], cfg.accel, cfg.damping, cfg.dt)  # (B,)
        w = lag(state.vel[:, 1], act[:, 1], cfg.yaw_accel, cfg.yaw_damping, cfg.dt)  # (B,)
        heading = wrap(state.heading + cfg.dt * w)
        return forward(state.pos, heading, cfg.dt * v), np.stack([v, w], axis=1), heading

    def observe(self, state: PlanarState) -> np.ndarray:
        return heading_obs(state, state.vel[:, 0], state.vel[:, 1])

    def waypoint_controller(self, state: PlanarState, obs: np.ndarray, info: dict, gain_turn: float = 6.0
                            ) -> np.ndarray:
        """Thrust and torque toward ``info["waypoint"]``, ``(B, 2)``: the yaw rate and speed a unicycle
        controller would command, each reached through its own first-order lag."""
        cfg = self.config
        d = np.asarray(info["waypoint"]) - np.asarray(info["position"])  # (B, 2)
        angle = wrap(np.arctan2(d[:, 1], d[:, 0]) - state.heading)  # (B,)
        w_max = cfg.yaw_accel / cfg.yaw_damping
        w_des = np.clip(gain_turn * angle, -w_max, w_max)
        v_des = coast_speed(cfg, info, np.maximum(np.cos(angle), 0.0))
        torque = lag_input(state.vel[:, 1], w_des, cfg.yaw_accel, cfg.yaw_damping, cfg.dt)
        thrust = lag_input(state.vel[:, 0], v_des, cfg.accel, cfg.damping, cfg.dt)
        return np.clip(np.stack([thrust, torque], axis=1), -1.0, 1.0).astype(np.float32)


class RoverEnv(PlanarEnv):
    env_id = ENV_ID
    core_cls = RoverCore
    make_config = staticmethod(make_config)


make_limited, RoverVectorEnv = entry_points(RoverEnv)  # the registered entry points
