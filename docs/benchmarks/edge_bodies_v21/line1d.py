"""1-D waypoint space: a point on a line, 1-D velocity action, 50 steps."""
import gymnasium as gym
import numpy as np


class Line1D(gym.Env):
    observation_space = gym.spaces.Box(-5.0, 5.0, (2,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.abs(d[0])), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(1)
        self.goal = self.np_random.uniform(-2.0, 2.0, 1)
        return self._obs_info()

    def step(self, action):
        self.pos = np.clip(self.pos + 0.1 * np.clip(action, -1.0, 1.0), -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, -float(np.abs(self.goal - self.pos)[0]), False, False, info


gym.register("Line1D-v0", entry_point=Line1D, max_episode_steps=50)
