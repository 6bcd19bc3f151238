"""3-D point driven by a 6-D action mixed by a fixed matrix; 50 steps."""
import gymnasium as gym
import numpy as np

MIX = np.random.default_rng(123).normal(size=(3, 6)) / np.sqrt(6)


class Point3D6A(gym.Env):
    observation_space = gym.spaces.Box(-5.0, 5.0, (6,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (6,), np.float32)

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        return np.concatenate([self.pos, self.goal]).astype(np.float32), info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(3)
        self.goal = self.np_random.uniform(-2.0, 2.0, 3)
        return self._obs_info()

    def step(self, action):
        v = MIX @ np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)
        self.pos = np.clip(self.pos + 0.1 * v, -5.0, 5.0)
        obs, info = self._obs_info()
        return obs, -float(np.linalg.norm(self.goal - self.pos)), False, False, info


gym.register("Point3D6A-v0", entry_point=Point3D6A, max_episode_steps=50)
