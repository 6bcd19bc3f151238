"""``shaped_es.train(config, out, callback=...)``: a run from Python, checked before anything is written, as
``shaped-es train``; the callback sees every row and can stop the run."""

import pytest

import shaped_es
from helpers import CARTPOLE_TINY
from shaped_es.config import ConfigError
from shaped_es.rundir.store import RunStore, StoreError


def test_train_from_python_with_a_callback(tmp_path):
    tests = []

    def until_solved(row):
        tests.append(row["test_reward_mean"])
        return row["test_reward_mean"] < 60  # False stops the run

    cfg = {**CARTPOLE_TINY, "executor": "inline", "es.sigma": 0.1}  # dotted keys, as --set
    rows = shaped_es.train(cfg, tmp_path / "r", callback=until_solved)
    assert rows and tests == [r["test_reward_mean"] for r in rows] and max(tests) >= 60
    assert len(RunStore(tmp_path / "r").read_metrics()) == len(rows) < CARTPOLE_TINY["generations"]
    with pytest.raises(StoreError, match="already holds a run"):
        shaped_es.train(cfg, tmp_path / "r")
    with pytest.raises(ConfigError, match="es.sigma"):
        shaped_es.train({**cfg, "es.sigma": -1}, tmp_path / "bad")
    assert not (tmp_path / "bad").exists()  # checked before anything is written


def test_a_yaml_file_or_a_run_config(tmp_path):
    cfg = shaped_es.RunConfig(env="CartPole-v1", generations=1, executor="inline", tensorboard=False,
                              es={"pairs": 2}, rollout={"test_episodes": 1})
    assert len(shaped_es.train(cfg, tmp_path / "a")) == 1
    assert len(shaped_es.train(tmp_path / "a" / "config.yaml", tmp_path / "b")) == 1  # a run's own config
