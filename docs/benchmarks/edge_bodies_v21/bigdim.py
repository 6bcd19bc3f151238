"""2-D point with a 200-D observation (position, goal, 196 lidar-like features) and an 8-D action
(mixed into a 2-D velocity by a fixed matrix). 50 steps."""
import gymnasium as gym
import numpy as np

MIX = np.random.default_rng(7).normal(size=(2, 8)) / np.sqrt(8)
ANG = np.linspace(0, 2 * np.pi, 196, endpoint=False)


class BigDim(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (200,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (8,), np.float32)

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        feat = np.cos(ANG - np.arctan2(d[1], d[0])) * np.linalg.norm(d) / 3
        return np.concatenate([self.pos, self.goal, feat]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        v = MIX @ np.clip(np.asarray(action, np.float64), -1.0, 1.0)
        self.pos = np.clip(self.pos + 0.1 * v, -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, -float(np.linalg.norm(self.goal - self.pos)), False, False, info


gym.register("BigDim-v0", entry_point=BigDim, max_episode_steps=50)
