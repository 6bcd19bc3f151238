"""HalfCheetah-v5 with timed forward waypoints in the (torso x, torso z) plane.

position  = torso (x, z) in world coordinates (MuJoCo body "torso").
waypoint  = where a body moving forward at TARGET_SPEED from its start (x0, z0) should be
            LOOKAHEAD steps from now: (x0 + v * dt * (t + LOOKAHEAD), z0). If the torso is already
            ahead of that point, the waypoint is put LOOKAHEAD steps of target speed ahead of the
            torso instead (never behind the body).
reward    = HalfCheetah-v5's own dense reward: forward velocity (dx/dt) - 0.1 * |a|^2.
episode   = 150 steps (7.5 s, dt = 0.05).
threshold = 75 (= mean net forward speed of ~0.5 m/s over the episode).
"""
import gymnasium as gym
import numpy as np
from gymnasium.envs.mujoco.half_cheetah_v5 import HalfCheetahEnv

TARGET_SPEED = 1.0  # m/s
LOOKAHEAD = 5  # steps (0.25 s at dt = 0.05)
HORIZON = 150


class CheetahWaypoints(HalfCheetahEnv):
    def _torso_xz(self):
        p = self.data.body("torso").xpos
        return np.array([p[0], p[2]], dtype=np.float64)

    def _waypoint(self, pos):
        lead = TARGET_SPEED * self.dt * LOOKAHEAD
        x_sched = self._x0 + TARGET_SPEED * self.dt * (self._t + LOOKAHEAD)
        x = pos[0] + lead if pos[0] > x_sched else x_sched
        return np.array([x, self._z0], dtype=np.float64)

    def _add_keys(self, info):
        pos = self._torso_xz()
        info["position"] = pos
        info["waypoint"] = self._waypoint(pos)
        return info

    def reset(self, *, seed=None, options=None):
        obs, info = super().reset(seed=seed, options=options)
        self._t = 0
        p = self._torso_xz()
        self._x0, self._z0 = float(p[0]), float(p[1])
        return obs, self._add_keys(info)

    def step(self, action):
        obs, reward, terminated, truncated, info = super().step(action)
        self._t += 1
        return obs, reward, terminated, truncated, self._add_keys(info)


gym.register(
    "CheetahWaypoints-v0",
    entry_point=CheetahWaypoints,
    max_episode_steps=HORIZON,
    reward_threshold=75.0,
)
