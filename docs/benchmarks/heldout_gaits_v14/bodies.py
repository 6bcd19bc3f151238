"""Three more Gymnasium MuJoCo bodies with waypoints, written as a new user would from the README, to test
whether the label probe tells never-paying bodies from paying ones before the first generation.

HopperWay-v0, Walker2dWay-v0: timed forward waypoints in the torso's (x, z) plane, as the cheetah's
  (a body moving forward at TARGET_SPEED from its start, LOOKAHEAD steps ahead; never behind the torso);
  the env's own dense reward (healthy + forward velocity - ctrl); early termination when unhealthy;
  150 steps.
AntNav-v0: the Ant reaching a random goal 2-4 m away in the plane; spatial waypoints every 0.5 m on the
  start-goal line, consumed when the torso is within 0.3 m; reward = progress toward the goal (m, x10)
  - 0.05 |a|^2 + 0.05 healthy; obs = Ant's obs (no x, y) + (goal - xy) + (waypoint - xy); 200 steps.
"""
import gymnasium as gym
import numpy as np
from gymnasium.envs.mujoco.hopper_v5 import HopperEnv
from gymnasium.envs.mujoco.walker2d_v5 import Walker2dEnv
from gymnasium.envs.mujoco.ant_v5 import AntEnv

TARGET_SPEED = 1.0
LOOKAHEAD = 5


class ForwardWaypoints(gym.Wrapper):
    """The torso's (x, z) and a forward waypoint moving at TARGET_SPEED from the start, LOOKAHEAD steps ahead
    (never behind the torso), added to ``info`` at reset and every step."""

    def _keys(self, info: dict) -> dict:
        body = self.env.unwrapped
        torso = np.array(body.data.body("torso").xpos[[0, 2]], dtype=np.float64)
        ahead = TARGET_SPEED * body.dt * LOOKAHEAD
        due = self.start[0] + TARGET_SPEED * body.dt * (self.t + LOOKAHEAD)
        x = torso[0] + ahead if torso[0] > due else due
        info["position"], info["waypoint"] = torso, np.array([x, self.start[1]], dtype=np.float64)
        return info

    def reset(self, *, seed=None, options=None):
        obs, info = self.env.reset(seed=seed, options=options)
        self.t = 0
        self.start = np.array(self.env.unwrapped.data.body("torso").xpos[[0, 2]], dtype=np.float64)
        return obs, self._keys(info)

    def step(self, action):
        obs, reward, terminated, truncated, info = self.env.step(action)
        self.t += 1
        return obs, reward, terminated, truncated, self._keys(info)


class AntNav(AntEnv):
    def __init__(self, **kw):
        super().__init__(**kw)
        lo = np.full(self.observation_space.shape[0] + 4, -np.inf, dtype=np.float64)
        self.observation_space = gym.spaces.Box(lo, -lo, dtype=np.float64)

    def _xy(self):
        return np.array(self.data.body("torso").xpos[:2], dtype=np.float64)

    def _obs(self, base):
        xy = self._xy()
        return np.concatenate([base, self._goal - xy, self._wp() - xy])

    def _wp(self):
        return self._wps[min(self._k, len(self._wps) - 1)]

    def _info(self, info):
        info["position"] = self._xy()
        info["waypoint"] = self._wp().copy()
        return info

    def reset(self, *, seed=None, options=None):
        base, info = super().reset(seed=seed, options=options)
        start = self._xy()
        ang = self.np_random.uniform(-np.pi, np.pi)
        dist = self.np_random.uniform(2.0, 4.0)
        self._goal = start + dist * np.array([np.cos(ang), np.sin(ang)])
        n = int(np.ceil(dist / 0.5))
        self._wps = [start + (k / n) * (self._goal - start) for k in range(1, n + 1)]
        self._k = 0
        self._prev = np.linalg.norm(self._goal - start)
        return self._obs(base), self._info(info)

    def step(self, action):
        base, _, terminated, truncated, info = super().step(action)
        xy = self._xy()
        while self._k < len(self._wps) - 1 and np.linalg.norm(self._wps[self._k] - xy) < 0.3:
            self._k += 1
        d = np.linalg.norm(self._goal - xy)
        a = np.asarray(action, dtype=np.float64)
        reward = 10.0 * (self._prev - d) - 0.05 * float(a @ a) + 0.05 * float(self.is_healthy)
        self._prev = d
        return self._obs(base), reward, terminated, truncated, self._info(info)


gym.register("HopperWay-v0", entry_point=lambda **kw: ForwardWaypoints(HopperEnv(**kw)), max_episode_steps=150,
             reward_threshold=150.0)
gym.register("Walker2dWay-v0", entry_point=lambda **kw: ForwardWaypoints(Walker2dEnv(**kw)), max_episode_steps=150,
             reward_threshold=150.0)
gym.register("AntNav-v0", entry_point=AntNav, max_episode_steps=200, reward_threshold=15.0,
             kwargs={"include_cfrc_ext_in_observation": False})
