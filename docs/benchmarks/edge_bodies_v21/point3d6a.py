"""3-D point driven by a 6-D action mixed by a fixed matrix; 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint

MIX = np.random.default_rng(123).normal(size=(3, 6)) / np.sqrt(6)


class Point3D6A(GoalPoint):
    dim = 3
    observation_space = gym.spaces.Box(-5.0, 5.0, (6,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (6,), np.float32)

    def velocity(self, action):
        return MIX @ np.clip(np.asarray(action, dtype=np.float64), -1.0, 1.0)


gym.register("Point3D6A-v0", entry_point=Point3D6A, max_episode_steps=50)
