"""A user's env for ``--method shaped``: Gymnasium's MuJoCo ``Reacher-v5`` with the two-key waypoint
contract added by a wrapper, nothing else (no batched core, no controller hook).

Reacher's rewards are never positive (``-distance - control cost``), the case the paper's positive-return
filter of M_phi's data never serves; the shaped method's defaults train here anyway (README, "Your own
env"). Waypoint space: the fingertip's (x, y); the next local waypoint is the point ``step`` metres
along the straight line from the fingertip toward the target (the target itself once it is nearer).

    cd examples && shaped-es train --env reacher_waypoints:ReacherWaypoints-v0 --method shaped --out ../runs/reacher

(needs ``pip install -e ".[examples]"`` for MuJoCo's Gymnasium envs.)
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np


class ReacherWaypoints(gym.Wrapper):
    """``Reacher-v5`` whose ``info`` carries ``position`` (fingertip x, y) and ``waypoint``."""

    def __init__(self, step: float = 0.02, **kwargs):
        super().__init__(gym.make("Reacher-v5", **kwargs))
        self.step_size = float(step)

    def _contract(self, info: dict) -> dict:
        u = self.env.unwrapped
        tip = u.get_body_com("fingertip")[:2].astype(np.float64)  # (2,)
        target = u.get_body_com("target")[:2].astype(np.float64)  # (2,)
        d = target - tip
        dist = float(np.linalg.norm(d))
        wp = target if dist <= self.step_size else tip + d * (self.step_size / dist)
        return {**info, "position": tip, "waypoint": wp}

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        return obs, self._contract(info)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        return obs, reward, terminated, truncated, self._contract(info)


gym.register("ReacherWaypoints-v0", entry_point=ReacherWaypoints, max_episode_steps=50)
