"""PPO on both built-in envs without any time-limit setting: the registered envs carry their preset's
horizon (``env.spec.max_episode_steps``), which sets PPO's env-step budget per generation."""

import gymnasium as gym
import pytest

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.baselines.ppo import env_time_limit
from shaped_es.cli.commands import main
from shaped_es.config import build_config
from shaped_es.rundir.store import RunStore

HORIZON = {"CarNav-v0": (250, 1000), "UR5Reach-v0": (100, 100)}  # (default preset, paper preset)


@pytest.mark.parametrize("env_id", list(HORIZON))
def test_registered_time_limit_follows_preset_and_overrides(env_id):
    default, paper = HORIZON[env_id]
    assert gym.make(f"shaped_es:{env_id}").spec.max_episode_steps == default
    assert gym.make(f"shaped_es:{env_id}", preset="paper").spec.max_episode_steps == paper
    assert gym.make(f"shaped_es:{env_id}", max_steps=37).spec.max_episode_steps == 37
    assert env_time_limit(build_config({"env": env_id, "method": "ppo"})) == default
    assert env_time_limit(build_config({"env": env_id, "method": "ppo",
                                        "env_kwargs": {"preset": "paper"}})) == paper
    env = gym.make(f"shaped_es:{env_id}", max_steps=5)
    env.reset(seed=0)
    ends = [env.step(env.action_space.sample())[3] for _ in range(5)]
    assert ends == [False] * 4 + [True]


@pytest.mark.parametrize("env_id", list(HORIZON))
def test_ppo_trains_on_builtin_env_without_time_limit_settings(env_id, tmp_path, capsys):
    out = tmp_path / "ppo"
    # small PPO rollouts to keep the test short; no rollout.max_steps, no ppo.steps_per_generation
    code = main(["train", "--env", env_id, "--method", "ppo", "--generations", "1", "--pairs", "1",
                 "--executor", "inline", "--set", "rollout.episodes=1", "--set", "rollout.test_episodes=2",
                 "--set", "ppo.n_steps=128", "--set", "ppo.batch_size=64", "--set", "ppo.n_epochs=1",
                 "--set", "policy.hidden=[8]", "--set", "tensorboard=false", "--quiet", "--out", str(out)])
    assert code == 0, capsys.readouterr().err
    (row,) = RunStore(out).read_metrics()
    budget = 2 * 1 * 1 * HORIZON[env_id][0]  # ES's max env steps per generation at the env's horizon
    assert int(row["gen_env_steps"]) == max(1, round(budget / 128)) * 128
    assert row["test_reward_mean"] not in ("", None)
