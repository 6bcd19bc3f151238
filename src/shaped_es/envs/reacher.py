"""``ReacherWay-v0``: Gymnasium's MuJoCo ``Reacher-v5`` (a torque-driven 2-link planar arm) with timed
waypoints from the start fingertip to the target, the suite's arm beside UR5Reach-v0.

The env is ``Reacher-v5`` itself (a subclass: same model, dynamics, observation, reward, seeding from
``self.np_random``) with the waypoint contract added to ``info`` and a waypoint controller:

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: joint torques (x 200, Reacher-v5's gear)
Observation        ``Box(-inf, inf, (10,))``: Reacher-v5's (cos, sin of the joints, target, joint
                   velocities, fingertip - target). No waypoints.
Reward             Reacher-v5's: ``reward_dist`` -|fingertip - target| + ``reward_ctrl`` -|a|^2
Episode            Reacher-v5's random start (arm near straight along +x) and target (within 0.2 of the
                   base); 50 steps (1 s)
info               ``position`` (2,) fingertip (x, y), ``waypoint`` (2,) where the schedule puts it after
                   the next step, ``target`` (2,), ``waypoint_index``, and Reacher-v5's reward terms
=================  ======================================================================================

Timed waypoints: after ``t`` steps the next waypoint is ``start + (target - start) * min(1, (t + 1) /
reach_steps)`` (``start``: the fingertip at reset): a straight line walked in ``reach_steps`` = 25 steps,
then the target.

Waypoint controller (``waypoint_controller``): resolved-rate control. Desired fingertip velocity
``gain * (waypoint - fingertip)``, joint velocities by damped least squares with the 2-link Jacobian
(links 0.1 and 0.11), torques ``kv * (qd_des - qd)`` clipped to ``[-1, 1]``.
Threshold (``reward_threshold`` -7): the controller scores -5.9 (mean of 20 episodes; Reacher-v5's own
threshold is -3.75 and a still arm about -43 less its random targets' luck); -7 is most of the way along
the schedule with a modest control cost.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.envs.mujoco.reacher_v5 import ReacherEnv

from shaped_es.envs.presets import preset_config

ENV_ID = "ReacherWay-v0"
REWARD_THRESHOLD = -7.0  # the controller's return (20 episodes) less a margin: see the module docstring
LINKS = (0.1, 0.11)  # Reacher-v5's link lengths: joint0 -> joint1, joint1 -> fingertip


@dataclass(frozen=True)
class ReacherWayConfig:
    max_steps: int = 50  # Reacher-v5's time limit
    reach_steps: int = 15  # the schedule reaches the target after this many steps
    reward_dist_weight: float = 1.0  # Reacher-v5's
    reward_control_weight: float = 1.0  # Reacher-v5's

    def validate(self) -> "ReacherWayConfig":
        if self.max_steps <= 0 or self.reach_steps <= 0:
            raise ValueError(f"{ENV_ID}: max_steps and reach_steps must be positive")
        return self

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


PRESETS = {"default": ReacherWayConfig()}


def make_config(preset: str = "default", **overrides: Any) -> ReacherWayConfig:
    return preset_config(ENV_ID, PRESETS, preset, overrides)


def timed_waypoint(start: np.ndarray, target: np.ndarray, k: int, reach_steps: int) -> np.ndarray:
    """Waypoint ``k`` of the schedule: ``start + (target - start) * min(1, k / reach_steps)``."""
    return start + (target - start) * min(1.0, k / reach_steps)


def fingertip(q: np.ndarray) -> np.ndarray:
    """Fingertip (x, y) of joint angles ``q`` ``(2,)`` (planar forward kinematics)."""
    l1, l2 = LINKS
    return np.array([l1 * np.cos(q[0]) + l2 * np.cos(q[0] + q[1]), l1 * np.sin(q[0]) + l2 * np.sin(q[0] + q[1])])


def jacobian(q: np.ndarray) -> np.ndarray:
    """d fingertip / d q, ``(2, 2)``."""
    l1, l2 = LINKS
    s0, c0, s01, c01 = np.sin(q[0]), np.cos(q[0]), np.sin(q[0] + q[1]), np.cos(q[0] + q[1])
    return np.array([[-l1 * s0 - l2 * s01, -l2 * s01], [l1 * c0 + l2 * c01, l2 * c01]])


def resolved_rate(obs: np.ndarray, position: np.ndarray, waypoint: np.ndarray, gain: float = 20.0,
                  damping_lambda: float = 0.15, kv: float = 0.1) -> np.ndarray:
    """Torque action ``(2,)`` in ``[-1, 1]`` moving the fingertip toward ``waypoint`` (module docstring)."""
    obs = np.asarray(obs, dtype=np.float64)
    q = np.arctan2(obs[2:4], obs[0:2])  # (2,) joint angles from (cos, sin)
    qd = obs[6:8]  # (2,) joint velocities
    v = gain * (np.asarray(waypoint, np.float64) - np.asarray(position, np.float64))  # (2,)
    J = jacobian(q)
    qd_des = J.T @ np.linalg.solve(J @ J.T + damping_lambda**2 * np.eye(2), v)  # (2,)
    return np.clip(kv * (qd_des - qd), -1.0, 1.0).astype(np.float32)


class ReacherWayEnv(ReacherEnv):
    """``Reacher-v5`` whose ``info`` carries ``position`` (fingertip) and a timed ``waypoint``."""

    def __init__(self, render_mode: str | None = None, preset: str = "default", **overrides: Any):
        self.config = make_config(preset, **overrides)
        super().__init__(render_mode=render_mode, reward_dist_weight=self.config.reward_dist_weight,
                         reward_control_weight=self.config.reward_control_weight)
        self._t = 0
        self._start = np.zeros(2)

    def _contract(self, info: dict) -> dict:
        tip = self.get_body_com("fingertip")[:2].astype(np.float64)  # (2,)
        target = self.get_body_com("target")[:2].astype(np.float64)  # (2,)
        k = min(self._t + 1, self.config.reach_steps)
        return {**info, "position": tip, "waypoint": timed_waypoint(self._start, target, k, self.config.reach_steps),
                "target": target, "waypoint_index": k}

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        obs, info = super().reset(seed=seed, options=options)
        self._t = 0
        self._start = self.get_body_com("fingertip")[:2].astype(np.float64)
        return obs, self._contract(info)

    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        self._t += 1
        return obs, reward, terminated, truncated, self._contract(info)

    def waypoint_controller(self, obs, info: dict) -> np.ndarray:
        """Resolved-rate control toward ``info["waypoint"]`` (``envs/core.py`` hook), ``(2,)``."""
        return resolved_rate(obs, info["position"], info["waypoint"])


def make_limited(**kwargs):
    """``ReacherWayEnv(**kwargs)`` under a ``TimeLimit`` of its config's max_steps (the entry point)."""
    env = ReacherWayEnv(**kwargs)
    return gym.wrappers.TimeLimit(env, env.config.max_steps)


make_limited.metadata = ReacherWayEnv.metadata
