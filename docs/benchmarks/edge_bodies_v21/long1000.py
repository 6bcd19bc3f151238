"""2-D point, 1000-step episodes (small steps); reward per step scaled by 1/100."""
import gymnasium as gym
from point import GoalPoint


class Long1000(GoalPoint):
    spacing, speed, reward_scale = 0.05, 0.005, 0.01


gym.register("Long1000-v0", entry_point=Long1000, max_episode_steps=1000)
