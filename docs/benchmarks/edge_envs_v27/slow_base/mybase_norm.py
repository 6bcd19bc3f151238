"""MyBase wrapped in gymnasium's NormalizeObservation at registration."""
import gymnasium as gym
from gymnasium.wrappers import NormalizeObservation

from mybase import MyBase


def make_normed(**kwargs):
    return NormalizeObservation(MyBase(**kwargs))


gym.register("MyBaseNorm-v0", entry_point=make_normed, max_episode_steps=60)
