"""``env_probe``: observations that are not one vector (a goal-conditioned env's ``Dict``) are flattened the same
way wherever an env is made, so a run, ``evaluate``, PPO and ``load_policy`` read the same vector; spaces
Gymnasium cannot flatten are refused in one line."""

import gymnasium as gym
import numpy as np
import pytest

from shaped_es.cli.check_env import OK, check_env, trains_with
from shaped_es.rollout import EnvError, EnvSpecError, env_dims, flattened_from, make_env, probe_env
from tests.helpers import train


class GoalPoint(gym.Env):
    """A 2-D point with a goal, observed as Gymnasium-Robotics' goal envs are: a Dict of three Boxes."""

    observation_space = gym.spaces.Dict({
        "observation": gym.spaces.Box(-5, 5, (2,), np.float64),
        "desired_goal": gym.spaces.Box(-5, 5, (2,), np.float64),
        "achieved_goal": gym.spaces.Box(-5, 5, (2,), np.float64)})
    action_space = gym.spaces.Box(-1, 1, (2,), np.float32)

    def _obs(self):
        return {"observation": self.x.copy(), "desired_goal": self.g.copy(), "achieved_goal": self.x + 0.5}

    def _info(self):
        d = self.g - self.x
        return {"position": self.x.copy(), "waypoint": self.x + 0.3 * d / max(np.linalg.norm(d), 1e-9)}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.g = self.np_random.uniform(-1, 1, 2), self.np_random.uniform(-2, 2, 2)
        return self._obs(), self._info()

    def step(self, action):
        before = np.linalg.norm(self.g - self.x)
        self.x = np.clip(self.x + 0.1 * np.asarray(action, np.float64), -5, 5)
        return self._obs(), float(10 * (before - np.linalg.norm(self.g - self.x))), False, False, self._info()


class Sequenced(GoalPoint):
    observation_space = gym.spaces.Sequence(gym.spaces.Box(-5, 5, (2,), np.float64))


class MissingKey(GoalPoint):
    def _obs(self):
        return {"observation": self.x.copy(), "desired_goal": self.g.copy()}  # achieved_goal left out


class ColumnActions(GoalPoint):  # a new user's (2, 1) action column
    action_space = gym.spaces.Box(-1, 1, (2, 1), np.float32)


gym.register("GoalPointDict-v0", entry_point=GoalPoint, max_episode_steps=20)
gym.register("ColumnActionsPoint-v0", entry_point=ColumnActions, max_episode_steps=20)
gym.register("MissingKeyPoint-v0", entry_point=MissingKey, max_episode_steps=20)
gym.register("SequencedPoint-v0", entry_point=Sequenced, max_episode_steps=20)


def test_a_dict_observation_is_flattened_in_gymnasiums_order():
    env = make_env("GoalPointDict-v0")
    obs, _ = env.reset(seed=3)
    assert isinstance(flattened_from(env), gym.spaces.Dict) and env_dims(env) == (6, 2)
    raw = env.unwrapped._obs()
    # gymnasium.spaces.flatten's order: the Dict's keys sorted (achieved_goal, desired_goal, observation)
    np.testing.assert_array_equal(obs, np.concatenate([raw["achieved_goal"], raw["desired_goal"],
                                                       raw["observation"]]))
    assert flattened_from(make_env("CarNav-v0")) is None  # a flat Box is left as it is


def test_a_space_gymnasium_cannot_flatten_is_one_line():
    with pytest.raises(EnvSpecError) as err:
        probe_env("SequencedPoint-v0")
    assert "\n" not in str(err.value) and "Gymnasium can flatten" in str(err.value) and "Sequence" in str(err.value)


def test_a_box_of_two_axes_is_refused_with_the_way_round():
    """A new user's Box (2, 1) was refused with no word on what to declare instead; train and check-env say it."""
    hint = "; declare it of shape (2,) and reshape inside step: action = np.reshape(action, (2, 1))"
    with pytest.raises(EnvSpecError) as err:
        probe_env("ColumnActionsPoint-v0")
    assert str(err.value).endswith("got Box(-1.0, 1.0, (2, 1), float32)" + hint)
    spaces = next(c for c in check_env("ColumnActionsPoint-v0") if c.name == "spaces")
    assert spaces.detail.endswith("got Box(-1.0, 1.0, (2, 1), float32)" + hint)


def test_check_env_says_which_checks_wait_for_the_spaces(capsys):
    """check-env stops at a spaces FAIL; its last line says the other checks run once the spaces pass (a new user
    read the short list as every check passing)."""
    from shaped_es.cli import main

    assert main(["check-env", "ColumnActionsPoint-v0"]) == 1
    out = capsys.readouterr().out.strip().splitlines()
    assert out[-1] == ("ColumnActionsPoint-v0 cannot train here: fix the FAIL line(s) above (the time limit, episode, "
                       "waypoint and reward checks run once the spaces pass)")


def test_a_reset_that_breaks_its_own_space_is_the_envs_error_in_one_line():
    """A new user's Dict env without one of its keys: Gymnasium's checker asserts in reset, which a shaped run's
    pre-run check reported as an internal error."""
    from shaped_es.config import build_config
    from shaped_es.guides.shaped_setup import waypoint_dim

    cfg = build_config({"env": "MissingKeyPoint-v0", "method": "shaped"})
    with pytest.raises(EnvError) as err:
        waypoint_dim(cfg)
    assert "\n" not in str(err.value) and str(err.value).startswith("env 'MissingKeyPoint-v0' raised AssertionError")
    assert str(err.value).endswith("in reset(seed=0)") and "achieved_goal" in str(err.value)


def test_check_env_passes_a_dict_env_and_says_it_flattened_it():
    checks = check_env("GoalPointDict-v0")
    spaces = next(c for c in checks if c.name == "spaces")
    assert spaces.status == OK and "6 floats (its Dict observations flattened" in spaces.detail
    assert trains_with(checks) == ["vanilla", "guided", "cmaes", "shaped", "shaped_cmaes", "ppo"]


def test_a_shaped_run_on_a_dict_env_and_its_policy_read_the_same_vector(tmp_path):
    from shaped_es import load_policy
    from shaped_es.trained.evaluate import evaluate_run

    store = train(tmp_path / "run", {"env": "GoalPointDict-v0", "method": "shaped", "generations": 2,
                                     "executor": "inline", "es": {"pairs": 4}})
    policy = load_policy(store.root, "mean")
    env = policy.make_env()
    obs, _ = env.reset(seed=0)
    assert obs.shape == (6,) and policy.observation_space.shape == (6,)
    assert np.asarray(policy.predict(obs)).shape == (2,)
    # one observation as the env itself gives it (a dict) is flattened the same way
    np.testing.assert_array_equal(policy.predict(env.unwrapped._obs()), policy.predict(obs))
    # evaluate's episodes (its own rollouts) and the loaded policy driving policy.make_env() agree
    result = evaluate_run(store.root, episodes=1, which="mean", seed=5, executor="inline")
    obs, _ = env.reset(seed=int(result["episode_seeds"][0]))
    total, done = 0.0, False
    while not done:
        obs, r, term, trunc, _ = env.step(policy.predict(obs))
        total, done = total + r, term or trunc
    assert total == pytest.approx(result["episode_returns"][0], rel=1e-5)
