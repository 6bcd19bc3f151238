"""``shaped_es.load_policy``: a trained run's policy driving a ``gymnasium.make`` env returns exactly what
``shaped-es evaluate`` reports on the same episode seeds (ES and PPO runs; the same states and actions
step for step), single and batched ``predict`` agree, and ``to_torch`` gives the same actions."""

import gymnasium as gym
import numpy as np
import pytest
import torch

from shaped_es import evaluation_seeds, load_policy
from shaped_es.cli.commands import main
from shaped_es.trained.evaluate import evaluate_run

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
    np.testing.assert_array_equal(ev["episode_returns"], ours)  # bit for bit (README)
    assert ev["reward_mean"] == ours.mean()
    assert ev["policy_generation"] == policy.generation and ev["checkpoint_generations"] == 2


@pytest.mark.parametrize("name", ["es", "ppo"])
def test_the_best_policy_names_its_generation(runs, name, tmp_path):
    """The best policy comes from the first generation whose test reward is the run's best (counted as
    generations done), also for checkpoints written before this was recorded (read from metrics.csv)."""
    import json
    import shutil

    from shaped_es.rundir.store import RunStore

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
        if name == "ppo":  # SB3's batched torch forward: the same up to float rounding
            np.testing.assert_allclose(policy.predict(obs[i]), batch[i], rtol=1e-5, atol=1e-6)
        else:  # ES: each row on its own, bit for bit
            np.testing.assert_array_equal(policy.predict(obs[i]), batch[i])
    module = policy.to_torch()
    assert isinstance(module, torch.nn.Module)
    with torch.no_grad():
        t = module(torch.from_numpy(obs)).numpy()
    np.testing.assert_allclose(t, batch, rtol=1e-5, atol=1e-5)
    if isinstance(policy.action_space, gym.spaces.Box):
        assert batch.shape == (5, policy.action_space.shape[0])
        assert all(policy.action_space.contains(a) for a in batch)


def test_evaluate_steps_what_the_gymnasium_loop_steps(runs):
    """evaluate's lock-step batch (the env's vectorized core, one policy forward for all episodes) sees
    the same observations and takes the same actions, bit for bit, as load_policy(...).predict driving
    a plain gymnasium.make env one observation at a time: on a chaotic task (a driving policy) any
    difference in the last bits grows until an episode ends differently."""
    from dataclasses import replace

    from shaped_es.rollout import policy_episode_tasks, run_task

    policy = load_policy(runs["es"])
    seeds = evaluation_seeds(6, SEED)
    (task,) = policy_episode_tasks(policy.env_id, policy.env_kwargs, policy.spec, policy.theta,
                                   np.array(seeds), workers=1, max_steps=policy.max_steps, rowwise=True)
    res = run_task(replace(task, record=True))  # evaluate's rollout of the 6 episodes, recorded
    tr = res.transitions[0]
    env = policy.make_env()
    for e, s in enumerate(seeds):
        obs, _ = env.reset(seed=s)
        states, actions, done = [], [], False
        while not done:
            action = policy.predict(obs)
            states.append(obs)
            actions.append(action)
            obs, _, term, trunc, _ = env.step(action)
            done = term or trunc
        mine = tr.episode == e
        np.testing.assert_array_equal(tr.state[mine], np.array(states, np.float32))
        np.testing.assert_array_equal(tr.action[mine], np.array(actions))  # CarNav's Box is [-1, 1]
    env.close()


def test_ppo_test_episodes_run_one_observation_per_forward(runs):
    """PPO's deterministic episodes (evaluate, test rewards) ask the policy one observation at a time, as
    predict(obs) does: a batched torch forward rounds a row differently depending on the batch."""
    from shaped_es.baselines.ppo_state import DeterministicEpisodes

    policy = load_policy(runs["ppo"])
    shapes = []

    class Spy:
        def predict(self, obs, deterministic):
            shapes.append(np.shape(obs))
            return policy.sb3_policy.predict(obs, deterministic=deterministic)

    runner = DeterministicEpisodes(policy.env_id, policy.env_kwargs, policy.max_steps)
    try:
        returns, _ = runner.run(Spy(), np.array(evaluation_seeds(EPISODES, SEED)))
    finally:
        runner.close()
    assert shapes and set(shapes) == {(1, policy.obs_dim)}
    np.testing.assert_array_equal(returns, _returns_with(policy, evaluation_seeds(EPISODES, SEED)))


def test_load_policy_errors(runs, tmp_path):
    from shaped_es.rundir.store import StoreError

    with pytest.raises(ValueError, match="which"):
        load_policy(runs["es"], which="worst")
    with pytest.raises(StoreError, match="not a run directory"):
        load_policy(tmp_path)
    with pytest.raises(ValueError, match="shape"):
        load_policy(runs["cartpole"]).predict(np.zeros(3))
