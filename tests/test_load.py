"""``shaped_es.load_policy``: a trained run's policy driving a ``gymnasium.make`` env returns what
``shaped-es evaluate`` reports on the same episode seeds (ES and PPO runs), single and batched
``predict`` agree, and ``to_torch`` gives the same actions."""

import gymnasium as gym
import numpy as np
import pytest
import torch

from shaped_es import evaluation_seeds, load_policy
from shaped_es.cli import main
from shaped_es.evaluate import evaluate_run

EPISODES, SEED = 3, 12345
COMMON = ["--generations", "2", "--executor", "inline", "--pairs", "2", "--set", "rollout.episodes=1",
          "--set", "rollout.test_episodes=2", "--set", "policy.hidden=[8]", "--set", "tensorboard=false",
          "--quiet"]
PPO = ["--set", "ppo.n_steps=128", "--set", "ppo.n_epochs=1"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    out = {}
    for name, env_id, method, extra in [("es", "CarNav-v0", "vanilla", []), ("ppo", "CarNav-v0", "ppo", PPO),
                                        ("cartpole", "CartPole-v1", "cmaes", [])]:
        assert main(["train", "--env", env_id, "--method", method, *COMMON, *extra,
                     "--out", str(root / name)]) == 0
        out[name] = root / name
    return out


def _returns_with(policy, seeds):
    """Episodes on a plain gymnasium.make env driven by policy.predict, one observation at a time."""
    env = gym.make(policy.env_id, **policy.env_kwargs)  # the built-in ids are registered on import
    out = []
    for s in seeds:
        obs, _ = env.reset(seed=int(s))
        total, done = 0.0, False
        while not done:
            action = policy.predict(obs)
            assert env.action_space.contains(action)
            obs, r, term, trunc, _ = env.step(action)
            total += float(r)
            done = term or trunc
        out.append(total)
    env.close()
    return np.array(out)


@pytest.mark.parametrize("name", ["es", "ppo", "cartpole"])
@pytest.mark.parametrize("which", ["best", "mean"])
def test_load_policy_returns_what_evaluate_reports(runs, name, which):
    policy = load_policy(runs[name], which=which)
    assert policy.checkpoint_generation == 2 and policy.which == which
    ev = evaluate_run(runs[name], episodes=EPISODES, which=which, seed=SEED, executor="inline")
    seeds = evaluation_seeds(EPISODES, SEED)  # the public function gives evaluate's seeds
    assert ev["episode_seeds"] == seeds == policy.evaluation_seeds(EPISODES, SEED)
    ours = _returns_with(policy, seeds)
    np.testing.assert_allclose(ev["episode_returns"], ours, rtol=1e-6, atol=1e-6)
    assert ev["reward_mean"] == pytest.approx(ours.mean(), rel=1e-6, abs=1e-6)
    assert ev["policy_generation"] == policy.generation and ev["checkpoint_generations"] == 2


@pytest.mark.parametrize("name", ["es", "ppo"])
def test_the_best_policy_names_its_generation(runs, name, tmp_path):
    """The best policy comes from the first generation whose test reward is the run's best (counted as
    generations done), also for checkpoints written before this was recorded (read from metrics.csv)."""
    import json
    import shutil

    from shaped_es.store import RunStore

    rows = RunStore(runs[name]).read_metrics()
    test = [float(r["test_reward_mean"]) for r in rows]
    assert load_policy(runs[name]).generation == int(np.argmax(test)) + 1
    assert load_policy(runs[name], which="mean").generation == 2
    old = tmp_path / "old"
    shutil.copytree(runs[name], old)
    meta_path = sorted((old / "checkpoints").glob("gen_*.json"))[-1]
    meta = json.loads(meta_path.read_text())
    del meta["best_generation"]
    meta_path.write_text(json.dumps(meta))
    assert load_policy(old).generation == int(np.argmax(test)) + 1


@pytest.mark.parametrize("name", ["es", "ppo", "cartpole"])
def test_predict_batches_and_torch_module(runs, name):
    policy = load_policy(runs[name])
    rng = np.random.default_rng(0)
    obs = rng.uniform(-1, 1, (5, policy.obs_dim)).astype(np.float32)
    batch = policy.predict(obs)
    assert len(batch) == 5
    for i in range(5):
        np.testing.assert_allclose(policy.predict(obs[i]), batch[i], rtol=1e-5, atol=1e-6)
    module = policy.to_torch()
    assert isinstance(module, torch.nn.Module)
    with torch.no_grad():
        t = module(torch.from_numpy(obs)).numpy()
    np.testing.assert_allclose(t, batch, rtol=1e-5, atol=1e-5)
    if isinstance(policy.action_space, gym.spaces.Box):
        assert batch.shape == (5, policy.action_space.shape[0])
        assert all(policy.action_space.contains(a) for a in batch)


def test_load_policy_errors(runs, tmp_path):
    from shaped_es.store import StoreError

    with pytest.raises(ValueError, match="which"):
        load_policy(runs["es"], which="worst")
    with pytest.raises(StoreError, match="not a run directory"):
        load_policy(tmp_path)
    with pytest.raises(ValueError, match="shape"):
        load_policy(runs["cartpole"]).predict(np.zeros(3))
