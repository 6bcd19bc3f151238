"""CarNav-v0's scripted waypoint controller (pure pursuit): exact values on fixed states, and the hook
the ``controller`` label source asks (core, single env, and the probe that says it is there)."""

import math

import gymnasium as gym
import numpy as np
import pytest

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.envs.carnav.config import make_config
from shaped_es.envs.carnav.controller import pure_pursuit
from shaped_es.envs.core import has_controller
from shaped_es.rollout import probe_env

CFG = make_config("default")


def test_pure_pursuit_exact_values():
    pos = np.zeros((3, 2))
    wp = np.array([[2.0, 0.0], [0.0, 3.0], [-4.0, 0.0]])  # ahead, 90 deg left, behind
    yaw, v = np.zeros(3), np.array([6.5, 2.0, 10.0])
    a = pure_pursuit(CFG, yaw, v, pos, wp)
    assert a.dtype == np.float32 and a.shape == (3, 2)
    assert a[0, 0] == 0.0 and a[0, 1] == 0.0  # straight ahead at the set speed: no steer, no throttle
    left = math.atan(CFG.wheelbase * 2 * math.sin(math.pi / 2) / 3.0) / CFG.max_steer
    assert a[1, 0] == pytest.approx(min(left, 1.0)) and a[1, 1] == 1.0  # 0.5 * (6.5 - 2) clipped to 1
    assert a[2, 1] == -1.0  # too fast: full brake (clipped)
    # the look-ahead never drops below 2.5 m: a waypoint 0.5 m to the side steers as one 2.5 m away
    near = pure_pursuit(CFG, np.zeros(1), np.full(1, 6.5), np.zeros((1, 2)), np.array([[0.4, 0.1]]))
    alpha = math.atan2(0.1, 0.4)
    assert near[0, 0] == pytest.approx(math.atan(CFG.wheelbase * 2 * math.sin(alpha) / 2.5) / CFG.max_steer)


def test_the_hook_on_the_core_and_on_the_env_agree():
    env = gym.make("shaped_es:CarNav-v0")
    assert has_controller(env) and probe_env("shaped_es:CarNav-v0").controller
    assert probe_env("CartPole-v1").controller is False
    obs, info = env.reset(seed=4)
    core = env.unwrapped.batch_core
    state, obs_b, info_b = core.reset(np.array([4]))
    for _ in range(5):
        a1 = env.unwrapped.waypoint_controller(obs, info)
        ab = core.waypoint_controller(state, obs_b, info_b)
        np.testing.assert_array_equal(a1, ab[0])
        np.testing.assert_array_equal(ab, pure_pursuit(CFG, state.yaw, state.v, info_b["position"],
                                                       info_b["waypoint"]))
        obs, *_, info = env.step(a1)
        state, obs_b, _, _, _, info_b = core.step(state, ab)
