"""``trained/evaluate.py``: what ``shaped-es evaluate`` adds beside the returns (the selection note) and what its
errors name."""

import gymnasium as gym
import numpy as np
import pytest
from helpers import CARTPOLE_TINY, train

from shaped_es.env_probe import EnvError
from shaped_es.trained.evaluate import evaluate_run, selection_note


class _Store:  # the metrics rows a note counts: 30 generations, each tested
    def read_metrics(self):
        return [{"test_reward_mean": "1.0"} for _ in range(30)]


def _result(returns, policy="best", chosen=9.16):
    return {"policy": policy, "test_reward_when_chosen": chosen, "policy_generation": 18,
            "episode_returns": list(returns)}


def test_a_best_policy_far_below_the_test_that_chose_it_gets_a_note():
    """A new user's slipping drive: chosen at 9.16, 6.90 on 15 new episodes (4 near 0); nothing said so."""
    fresh = [0.1, 9.4, 8.9, 0.8, 9.2, 9.0, 0.4, 9.5, 8.8, 9.1, 0.03, 9.3, 9.0, 8.7, 9.2]
    note = selection_note(_Store(), _result(fresh))
    r = np.array(fresh)
    assert note.startswith("note: the best policy's test reward 9.16 at generation 18 is the highest of the run's "
                           f"30 test means; on these 15 new episodes it scores {r.mean():.2f} +- "
                           f"{2 * r.std(ddof=1) / np.sqrt(15):.2f} (2 standard errors)")
    assert note.endswith("--policy mean evaluates the search's final mean; more --episodes narrow both")
    assert selection_note(_Store(), _result([9.0, 9.3, 9.1, 8.9])) is None  # within 2 standard errors
    assert selection_note(_Store(), _result(fresh, policy="mean", chosen=None)) is None
    assert selection_note(_Store(), _result([1.0])) is None  # one episode: no standard error


def test_a_best_policy_no_test_has_chosen_says_it_is_the_starting_one():
    """A new user's run stopped after its first checkpoint, before its first test's row: evaluate's best was the
    policy the run started from and said nothing."""
    note = selection_note(_Store(), _result([1.0, 2.0, 3.0], chosen=None))
    assert note.startswith("note: no test of this run has chosen a best policy yet")
    assert selection_note(_Store(), _result([1.0, 2.0], policy="mean", chosen=None)) is None


def test_an_env_error_in_evaluate_names_evaluate_not_a_generation(tmp_path, monkeypatch):
    """A new user's env raised in ``shaped-es evaluate``: the error said "(generation 0, episode seeds ...)",
    though evaluate runs no generation."""
    train(tmp_path / "r", {**CARTPOLE_TINY, "generations": 1, "executor": "inline"})

    def diverged(self, action):
        raise RuntimeError("simulator diverged")

    monkeypatch.setattr(gym.envs.classic_control.CartPoleEnv, "step", diverged)
    with pytest.raises(EnvError, match=r"raised RuntimeError: simulator diverged \(evaluate, the best policy, "
                                       r"episode seed \d+\)") as err:
        evaluate_run(tmp_path / "r", episodes=2, executor="inline")
    assert "generation" not in str(err.value)
