"""2-D point with a Discrete(5) action (stay, +x, -x, +y, -y); waypoint contract. 50 steps."""
import gymnasium as gym
import numpy as np
from point import GoalPoint

MOVES = np.array([[0, 0], [1, 0], [-1, 0], [0, 1], [0, -1]], dtype=np.float64)


class DiscAct(GoalPoint):
    action_space = gym.spaces.Discrete(5)

    def velocity(self, action):
        return MOVES[int(action)]


gym.register("DiscAct-v0", entry_point=DiscAct, max_episode_steps=50)
