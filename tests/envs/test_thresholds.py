"""envs/thresholds.py: one source of an env's success threshold for benchmark, train and the shaped guide."""

from __future__ import annotations

import math
from types import SimpleNamespace

import gymnasium as gym

from shaped_es.envs.thresholds import builtin_threshold, env_threshold, spec_threshold, threshold_of


def test_a_builtin_envs_threshold_and_where_it_comes_from():
    value, source = threshold_of("PointVel-v0")
    assert value == 8.5 and "reward_threshold" in source
    assert threshold_of("CarNav-v0")[0] == 200.0 and builtin_threshold("shaped_es.envs:CarNav-v0")[0] == 200.0
    assert threshold_of("CarNav-v0", {"preset": "default"})[0] == 200.0  # the default preset: the same scale


def test_a_rescaled_reward_has_no_default_threshold():
    """A setting that rescales the reward (another preset, a longer episode) leaves no threshold to count by."""
    assert threshold_of("CarNav-v0", {"preset": "paper"}) is None
    assert threshold_of("PointVel-v0", {"max_steps": 50}) is None


def test_a_users_env_brings_its_own_and_an_unknown_one_has_none():
    gym.register("ThresholdProbe-v0", entry_point="gymnasium.envs.classic_control:CartPoleEnv", reward_threshold=3.5)
    gym.register("NoThreshold-v0", entry_point="gymnasium.envs.classic_control:CartPoleEnv")
    gym.register("NanThreshold-v0", entry_point="gymnasium.envs.classic_control:CartPoleEnv",
                 reward_threshold=math.nan)
    try:
        assert threshold_of("ThresholdProbe-v0")[0] == 3.5
        assert spec_threshold("NoThreshold-v0") is None and spec_threshold("NanThreshold-v0") is None
        assert spec_threshold("no_such_module_here:Gone-v0") is None  # not importable: none, no error
        assert threshold_of("NeverRegistered-v0") is None
    finally:
        for env_id in ("ThresholdProbe-v0", "NoThreshold-v0", "NanThreshold-v0"):
            gym.registry.pop(env_id, None)


def test_a_run_configs_threshold():
    assert env_threshold(None) is None
    assert env_threshold(SimpleNamespace(env="Kart-v0", env_kwargs={}))[0] == threshold_of("Kart-v0")[0]
