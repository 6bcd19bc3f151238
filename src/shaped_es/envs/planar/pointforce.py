"""``PointForce-v0``: a 2-D point mass under force control with viscous damping (second order: the action
changes the velocity, not the position), going from a random start to a random goal along spatial
waypoints (the shared task: ``task.py``; batched core: ``core.py``).

Dynamics (semi-implicit Euler, ``dt`` = 0.1 s): ``v += dt * (accel * a - damping * v)``, ``p += dt * v``.
Full force in one direction settles at ``accel / damping`` = 0.5 units/s (0.05 a step, PointVel-v0's
speed) with a time constant of ``1 / damping`` = 1 s (10 steps).

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: force (acceleration ``accel * a``, 0.5 units/s^2 at +-1)
Observation        ``Box(-inf, inf, (6,))``: position (2), velocity (2), goal - position (2). No waypoints.
Reward             ``reward_progress`` 10 x the step's progress toward the goal / the start-goal distance +
                   ``reward_step`` -0.01
Episode            random start and goal 0.5-1.5 apart, at rest; terminates within 0.05 of the goal; 100
                   steps
info               as PointVel-v0: ``position``, ``waypoint`` (every 0.1 on the line, consumed when reached
                   or passed), ``goal``, ``waypoint_index``, ``num_waypoints``, ``is_success``, reward terms
=================  ======================================================================================

Waypoint controller: full force along the velocity error ``v_des - v`` with ``v_des`` the terminal speed
toward the waypoint (``unit_norm(gain * (v_des - v) + v_des / v_max)``).
Threshold (``reward_threshold`` 8.5): the controller scores 9.38 (mean of 20 episodes, min 9.19); 8.5 is
the goal reached with a path's step cost well above the controller's, or nearly reached. Vanilla-ES
(defaults) first reaches it at generation 39 and 45 (seeds 0, 1); its generation-0 test reward is 0 to 3.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shaped_es.envs.planar.core import PlanarCore, PlanarState
from shaped_es.envs.planar.env import PlanarEnv, config_maker, entry_points
from shaped_es.envs.planar.heading import lag
from shaped_es.envs.planar.task import PlanarTaskConfig, unit_norm

ENV_ID = "PointForce-v0"
REWARD_THRESHOLD = 8.5  # the controller's 9.38 (20 episodes) less a margin: see the module docstring


@dataclass(frozen=True)
class PointForceConfig(PlanarTaskConfig):
    accel: float = 0.5  # action +-1 -> +- this acceleration (units / s^2, per axis)
    damping: float = 1.0  # viscous damping (1 / s)

    def validate(self):
        if self.accel <= 0 or self.damping < 0:
            raise ValueError(f"{ENV_ID}: accel must be positive and damping >= 0")
        return super().validate()


PRESETS = {"default": PointForceConfig()}
make_config = config_maker(ENV_ID, PRESETS)


class PointForceCore(PlanarCore):
    obs_dim = 6

    def move(self, state: PlanarState, act: np.ndarray):
        cfg = self.config
        vel = lag(state.vel, act, cfg.accel, cfg.damping, cfg.dt)  # (B, 2)
        return state.pos + cfg.dt * vel, vel, state.heading

    def observe(self, state: PlanarState) -> np.ndarray:
        return np.concatenate([state.pos, state.vel, state.goal - state.pos], axis=1).astype(np.float32)

    def waypoint_controller(self, state: PlanarState, obs: np.ndarray, info: dict, gain: float = 4.0
                            ) -> np.ndarray:
        """Full force toward the velocity that heads for ``info["waypoint"]`` at the terminal speed,
        ``(B, 2)``."""
        cfg = self.config
        v_max = cfg.accel / max(cfg.damping, 1e-9)  # terminal speed at full force
        d = np.asarray(info["waypoint"]) - np.asarray(info["position"])  # (B, 2)
        v_des = v_max * unit_norm(d / (v_max * cfg.dt))  # (B, 2) slower when the waypoint is within a step
        return unit_norm(gain * (v_des - state.vel) + v_des / v_max).astype(np.float32)


class PointForceEnv(PlanarEnv):
    env_id = ENV_ID
    core_cls = PointForceCore
    make_config = staticmethod(make_config)


make_limited, PointForceVectorEnv = entry_points(PointForceEnv)  # the registered entry points
