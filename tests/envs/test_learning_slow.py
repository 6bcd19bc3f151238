"""Vanilla-ES learns both built-in envs far beyond a random policy (minutes: ``pytest -m slow``).

The random policy samples uniform actions; its mean return over 15 test episodes is measured here, not
hard-coded. Budgets are the default presets' (seed 0, 2 workers); the reference benchmark in ``docs/``
shows the same runs' curves.
"""

import numpy as np
import pytest

import shaped_es.envs  # noqa: F401 - registers the built-in envs
from shaped_es.config import build_config
from shaped_es.rollout import make_env
from shaped_es.rundir.store import RunStore
from shaped_es.trainer import Trainer

pytestmark = pytest.mark.slow


def random_policy_return(env_id: str, episodes: int = 15) -> float:
    env = make_env(env_id)
    returns = []
    for ep in range(episodes):
        env.reset(seed=10_000 + ep)
        env.action_space.seed(ep)
        total, done = 0.0, False
        while not done:
            _, r, term, trunc, _ = env.step(env.action_space.sample())
            total, done = total + float(r), term or trunc
        returns.append(total)
    env.close()
    return float(np.mean(returns))


@pytest.mark.parametrize("env_id, generations, margin", [("CarNav-v0", 80, 100.0), ("UR5Reach-v0", 60, 40.0)])
def test_vanilla_es_beats_a_random_policy_by_a_wide_margin(tmp_path, env_id, generations, margin):
    cfg = build_config({"env": env_id, "method": "vanilla", "generations": generations, "seed": 0,
                        "workers": 2, "tensorboard": False, "rollout": {"test_every": 5}})
    store = RunStore(tmp_path / "run")
    store.create(cfg)
    Trainer(cfg, store, progress=False).run()
    best = float(store.read_metrics()[-1]["test_reward_best_so_far"])
    baseline = random_policy_return(env_id)
    assert best > baseline + margin, (best, baseline)
