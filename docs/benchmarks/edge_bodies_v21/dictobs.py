"""2-D point with a goal-conditioned Dict observation (observation, achieved_goal, desired_goal). 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint


class DictObs(GoalPoint):
    observation_space = gym.spaces.Dict({
        "observation": gym.spaces.Box(-5.0, 5.0, (2,), np.float32),
        "achieved_goal": gym.spaces.Box(-5.0, 5.0, (2,), np.float32),
        "desired_goal": gym.spaces.Box(-5.0, 5.0, (2,), np.float32),
    })

    def observe(self):
        return {"observation": self.pos.astype(np.float32), "achieved_goal": self.pos.astype(np.float32),
                "desired_goal": self.goal.astype(np.float32)}


gym.register("DictObs-v0", entry_point=DictObs, max_episode_steps=50)
