"""2-D point carrying an unstable tilt; the episode terminates (falls) when |tilt| > 1, typically after
10-30 steps under random actions. Reward: +1 per step alive minus distance to goal. 100 steps."""
import gymnasium as gym
import numpy as np


class Falls(gym.Env):
    observation_space = gym.spaces.Box(-10.0, 10.0, (5,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

    def _obs_info(self):
        d = self.goal - self.pos
        step = min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-9))
        info = {"position": self.pos.copy(), "waypoint": self.pos + step * d}
        obs = np.concatenate([self.pos, self.goal, [self.tilt]]).astype(np.float32)
        return obs, info

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos = np.zeros(2)
        self.tilt = float(self.np_random.uniform(-0.05, 0.05))
        self.goal = self.np_random.uniform(-2.0, 2.0, 2)
        return self._obs_info()

    def step(self, action):
        a = np.clip(action, -1.0, 1.0)
        self.pos = np.clip(self.pos + 0.1 * a, -10, 10)
        self.tilt = 1.15 * self.tilt + 0.05 * float(a[0] - a[1]) + float(self.np_random.normal(0, 0.02))
        fell = abs(self.tilt) > 1.0
        self.tilt = float(np.clip(self.tilt, -2.0, 2.0))
        obs, info = self._obs_info()
        r = 1.0 - float(np.linalg.norm(self.goal - self.pos)) - (10.0 if fell else 0.0)
        return obs, r, fell, False, info


gym.register("Falls-v0", entry_point=Falls, max_episode_steps=100)
