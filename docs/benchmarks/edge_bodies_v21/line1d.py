"""1-D waypoint space: a point on a line, 1-D velocity action, 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint


class Line1D(GoalPoint):
    dim = 1
    observation_space = gym.spaces.Box(-5.0, 5.0, (2,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)


gym.register("Line1D-v0", entry_point=Line1D, max_episode_steps=50)
