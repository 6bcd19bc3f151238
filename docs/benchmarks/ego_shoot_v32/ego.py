"""Egocentric versions of three suite bodies: the same dynamics, waypoints and rewards, but the observation keeps
only what the body senses about itself and its goal (its speed, steering or yaw rate, the goal in its own frame)
and drops its world position and heading, as a robot with odometry-free, goal-relative sensing sees itself.

    EgoUnicycle-v0  Unicycle-v0 without obs[0:4] (position, cos/sin heading): the goal in the body frame (2)
    EgoRover-v0     Rover-v0 without obs[0:4]: forward speed, yaw rate, the goal in the body frame (4)
    EgoKart-v0      Kart-v0 without obs[0:4]: speed, steering angle, the goal in the body frame (4)

The waypoint controller is the suite body's own, fed the full observation it was written for. Thresholds: the
suite bodies' own (a policy cannot need the world pose to reach a goal it sees in its own frame; the controllers
themselves steer by the goal's body-frame angle).
"""

import gymnasium as gym
import numpy as np

import shaped_es.envs  # noqa: F401 - registers the suite bodies


class Ego(gym.ObservationWrapper):
    DROP = 4  # position (2), cos and sin of the heading (2)

    def __init__(self, env):
        super().__init__(env)
        n = env.observation_space.shape[0] - self.DROP
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (n,), np.float32)
        self._full = None

    def observation(self, obs):
        self._full = obs
        return np.asarray(obs[self.DROP:], np.float32)

    def waypoint_controller(self, obs, info):
        return self.env.unwrapped.waypoint_controller(self._full, info)


def _maker(base):
    def make(**kwargs):
        return Ego(gym.make(base, **kwargs))
    return make


for _base, _thr in (("Unicycle-v0", 8.5), ("Rover-v0", 8.0), ("Kart-v0", 8.0)):
    gym.register(f"Ego{_base}", entry_point=_maker(_base), reward_threshold=_thr)
