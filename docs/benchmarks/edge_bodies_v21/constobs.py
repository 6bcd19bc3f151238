"""2-D point with a constant (zero-variance) observation dimension (always 1.0) and one always 0. 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint


class ConstObs(GoalPoint):
    observation_space = gym.spaces.Box(-5.0, 5.0, (6,), np.float32)

    def observe(self):
        return np.concatenate([self.pos, [1.0], self.goal, [0.0]]).astype(np.float32)


gym.register("ConstObs-v0", entry_point=ConstObs, max_episode_steps=50)
