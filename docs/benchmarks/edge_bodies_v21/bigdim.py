"""2-D point with a 200-D observation (position, goal, 196 lidar-like features) and an 8-D action
(mixed into a 2-D velocity by a fixed matrix). 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint

MIX = np.random.default_rng(7).normal(size=(2, 8)) / np.sqrt(8)
ANG = np.linspace(0, 2 * np.pi, 196, endpoint=False)


class BigDim(GoalPoint):
    observation_space = gym.spaces.Box(-10.0, 10.0, (200,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (8,), np.float32)

    def velocity(self, action):
        return MIX @ np.clip(np.asarray(action, np.float64), -1.0, 1.0)

    def observe(self):
        d = self.goal - self.pos
        feat = np.cos(ANG - np.arctan2(d[1], d[0])) * np.linalg.norm(d) / 3
        return np.concatenate([self.pos, self.goal, feat]).astype(np.float32)


gym.register("BigDim-v0", entry_point=BigDim, max_episode_steps=50)
