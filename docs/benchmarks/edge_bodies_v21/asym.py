"""Box action with asymmetric bounds low=[0,-2], high=[1,2]: forward speed (>=0) and turn rate;
a unicycle-ish body with 2-D waypoints. 60 steps."""
import gymnasium as gym
import numpy as np


class Asym(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (6,), np.float32)
    action_space = gym.spaces.Box(np.array([0.0, -2.0], np.float32), np.array([1.0, 2.0], np.float32))

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        obs = np.concatenate([self.pos, self.goal, [np.cos(self.th), np.sin(self.th)]]).astype(np.float32)
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.th = float(self.np_random.uniform(-np.pi, np.pi))
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        a = np.clip(action, self.action_space.low, self.action_space.high)
        self.th += 0.2 * float(a[1])
        self.pos = np.clip(self.pos + 0.1 * float(a[0]) * np.array([np.cos(self.th), np.sin(self.th)]), -10, 10)
        obs, info = self._obs_info()
        return obs, -float(np.linalg.norm(self.goal - self.pos)), False, False, info


gym.register("Asym-v0", entry_point=Asym, max_episode_steps=60)
