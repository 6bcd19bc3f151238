"""2-D point, 1000-step episodes (small steps); reward per step scaled by 1/100."""
import gymnasium as gym
import numpy as np


class Long1000(gym.Env):
    observation_space = gym.spaces.Box(-5.0, 5.0, (4,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.05 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        self.pos = np.clip(self.pos + 0.005 * np.clip(action, -1.0, 1.0), -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, -0.01 * float(np.linalg.norm(self.goal - self.pos)), False, False, info


gym.register("Long1000-v0", entry_point=Long1000, max_episode_steps=1000)
