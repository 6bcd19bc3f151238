"""rollout/worker_envs.py: an env's exception during a rollout is one line naming the episode that raised it (a
new user's line named the task's three episode seeds, one of which had raised)."""

import sys

import numpy as np
import pytest
from gymnasium.envs.classic_control import CartPoleEnv as CartPole

from shaped_es.env_probe import EnvError
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask, run_task

SEEDS = (11, 12, 13)


def _task(generation=2) -> RolloutTask:
    spec = MLPSpec(4, 2, (4,))
    return RolloutTask("CartPole-v1", {}, spec, spec.init(0)[None], np.zeros(1, int), np.array([SEEDS]),
                       generation=generation, max_steps=10)


def _fails_on(monkeypatch, failing, where, fault):
    """CartPole whose ``where`` ("reset" or "step") calls ``fault()`` in the episode of seed ``failing``."""
    reset, step = CartPole.reset, CartPole.step

    def seeded_reset(self, *, seed=None, options=None):
        self._test_seed = seed
        if where == "reset" and seed == failing:
            fault()
        return reset(self, seed=seed, options=options)

    def failing_step(self, action):
        if where == "step" and self._test_seed == failing:
            fault()
        return step(self, action)

    monkeypatch.setattr(CartPole, "reset", seeded_reset)
    monkeypatch.setattr(CartPole, "step", failing_step)


def _diverged():
    raise RuntimeError("simulator diverged")


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize("where", ["reset", "step"])
def test_an_env_error_names_the_seed_of_the_episode_that_raised(monkeypatch, seed, where):
    _fails_on(monkeypatch, seed, where, _diverged)
    with pytest.raises(EnvError) as err:
        run_task(_task())
    line = str(err.value)
    assert line == f"env 'CartPole-v1' raised RuntimeError: simulator diverged (generation 3, episode seed {seed})"
    assert "Traceback" in err.value.detail and "simulator diverged" in err.value.detail  # error.log's text


def test_an_env_s_sys_exit_names_the_seed_of_the_episode_that_called_it(monkeypatch):
    _fails_on(monkeypatch, 13, "step", lambda: sys.exit("the simulator quit"))
    with pytest.raises(EnvError) as err:
        run_task(_task())
    assert str(err.value) == ("env 'CartPole-v1' called sys.exit('the simulator quit') during a rollout "
                              "(generation 3, episode seed 13); an env reports a failure by raising an exception")
