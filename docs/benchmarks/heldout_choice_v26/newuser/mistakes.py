"""Deliberate mistakes on top of mybots."""
import gymnasium as gym
import numpy as np
from mybots import Crawler, Valves


class Crawler2D(Crawler):
    """A 2-D nvec: [[3, 5]] (a user who wrote the nvec as a row)."""
    def __init__(self, render_mode=None):
        super().__init__(render_mode)
        self.action_space = gym.spaces.MultiDiscrete([[3, 5]])

    def step(self, action):
        return super().step(np.asarray(action).reshape(-1))


class CrawlerBadCtrl(Crawler):
    """Controller returns 3 numbers (gear, steer, and an extra)."""
    def waypoint_controller(self, obs, info):
        return np.append(super().waypoint_controller(obs, info), 0)


class CrawlerScalarCtrl(Crawler):
    """Controller returns a flat index gear*5+steer."""
    def waypoint_controller(self, obs, info):
        g, s = super().waypoint_controller(obs, info)
        return int(g * 5 + s)


class CrawlerOOR(Crawler):
    """Controller returns gear 3 (out of range) sometimes."""
    def waypoint_controller(self, obs, info):
        a = super().waypoint_controller(obs, info)
        a[0] = a[0] + 1
        return a


class CrawlerFloatCtrl(Crawler):
    """Controller returns float gear/steer."""
    def waypoint_controller(self, obs, info):
        return super().waypoint_controller(obs, info).astype(np.float32)


class ValvesBoolCtrl(Valves):
    """Controller returns a bool array."""
    def waypoint_controller(self, obs, info):
        return super().waypoint_controller(obs, info).astype(bool)


class ValvesBoolSpace(Valves):
    """A MultiBinary subclass whose dtype is bool."""
    def __init__(self, render_mode=None):
        super().__init__(render_mode)
        sp = gym.spaces.MultiBinary(6)
        sp.dtype = np.dtype(bool)
        self.action_space = sp


class Valves2D(Valves):
    """MultiBinary([2, 3]): a 2-D grid of jets."""
    def __init__(self, render_mode=None):
        super().__init__(render_mode)
        self.action_space = gym.spaces.MultiBinary([2, 3])

    def step(self, action):
        return super().step(np.asarray(action).reshape(6))

    def waypoint_controller(self, obs, info):
        return super().waypoint_controller(obs, info).reshape(2, 3)


class CrawlerStart(Crawler):
    """MultiDiscrete with start=[-1, -2] (gear -1 reverse..., steer -2..2); the step maps back."""
    def __init__(self, render_mode=None):
        super().__init__(render_mode)
        self.action_space = gym.spaces.MultiDiscrete([3, 5], start=[-1, -2])

    def step(self, action):
        a = np.asarray(action) - np.array([-1, -2])
        return super().step(a)

    def waypoint_controller(self, obs, info):
        return super().waypoint_controller(obs, info) + np.array([-1, -2])


for name, cls, T in [("Crawler2D", Crawler2D, 120), ("CrawlerBadCtrl", CrawlerBadCtrl, 120),
                     ("CrawlerScalarCtrl", CrawlerScalarCtrl, 120), ("CrawlerOOR", CrawlerOOR, 120),
                     ("CrawlerFloatCtrl", CrawlerFloatCtrl, 120), ("ValvesBoolCtrl", ValvesBoolCtrl, 100),
                     ("ValvesBoolSpace", ValvesBoolSpace, 100), ("Valves2D", Valves2D, 100),
                     ("CrawlerStart", CrawlerStart, 120)]:
    gym.register(f"{name}-v0", entry_point=cls, max_episode_steps=T)
