"""A user's env for ``--method shaped``: Gymnasium's MuJoCo ``Reacher-v5`` with the two-key waypoint
contract added by a wrapper, nothing else (no batched core, no controller hook) -- what you write for an
env you do not own.

The waypoints are the suite's (``shaped_es.envs.reacher.timed_waypoint``): a straight line from the start
fingertip to the target, walked on a 15-step schedule. The built-in ``ReacherWay-v0`` is the same task
on a batched core (one call steps a whole population; ~15x faster) with a waypoint controller, and is
what the suite (``shaped-es suite run``) trains.

Reacher's rewards are never positive (``-distance - control cost``), the case the paper's positive-return
filter of M_phi's data never serves; the shaped method's defaults train here anyway (README, "Your own
env").

    cd examples && shaped-es train --env reacher_waypoints:ReacherWaypoints-v0 --method shaped --out ../runs/reacher

(needs ``pip install -e ".[examples]"`` for Gymnasium's MuJoCo module, which imports imageio.)
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np

from shaped_es.envs.reacher import timed_waypoint


class ReacherWaypoints(gym.Wrapper):
    """``Reacher-v5`` whose ``info`` carries ``position`` (fingertip x, y) and ``waypoint``."""

    def __init__(self, reach_steps: int = 15, **kwargs):
        super().__init__(gym.make("Reacher-v5", **kwargs))
        self.reach_steps = int(reach_steps)
        self._t, self._start = 0, np.zeros(2)

    def _contract(self, info: dict) -> dict:
        u = self.env.unwrapped
        tip = u.get_body_com("fingertip")[:2].astype(np.float64)  # (2,)
        target = u.get_body_com("target")[:2].astype(np.float64)  # (2,)
        return {**info, "position": tip, "waypoint": timed_waypoint(self._start, target, self._t + 1, self.reach_steps)}

    def reset(self, **kwargs):
        obs, info = self.env.reset(**kwargs)
        self._t, self._start = 0, self.env.unwrapped.get_body_com("fingertip")[:2].astype(np.float64)
        return obs, self._contract(info)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._t += 1
        return obs, reward, terminated, truncated, self._contract(info)


gym.register("ReacherWaypoints-v0", entry_point=ReacherWaypoints, max_episode_steps=50)
