"""2-D point whose observation is in millimetres (values ~1e3); waypoints in metres. 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint


class BigObs(GoalPoint):
    observation_space = gym.spaces.Box(-5000.0, 5000.0, (4,), np.float32)

    def observe(self):
        return (1000.0 * np.concatenate([self.pos, self.goal])).astype(np.float32)


gym.register("BigObs-v0", entry_point=BigObs, max_episode_steps=50)
