"""PPO baseline: same metrics columns as ES, the ES trainer's test seeds, budget mapping, pickle-free resume."""

import types
import zipfile

import numpy as np
import pytest

from helpers import train
from shaped_es import seeding
from shaped_es.baselines.ppo_settings import PPOSettings, iterations_per_generation, ppo_settings
from shaped_es.config import ConfigError, build_config

TINY = {"env": "CartPole-v1", "seed": 1, "generations": 2, "es": {"pairs": 4}, "policy": {"hidden": [8]},
        "rollout": {"episodes": 2, "test_episodes": 3, "max_steps": 60}, "tensorboard": False,
        "executor": "inline"}
FAST = PPOSettings(n_steps=240, n_envs=2, batch_size=120, n_epochs=2)  # 2 iterations per generation


def _run(tmp_path, name, method, **over):
    cfg = build_config({**TINY, "method": method, **over})
    return cfg, train(tmp_path / name, cfg, ppo=FAST)


def test_iterations_per_generation_match_the_es_budget():
    cfg = build_config({**TINY, "rollout": {"episodes": 2, "max_steps": 100}})
    # ES max per generation: 2 * 4 pairs * 2 episodes * 100 steps = 1600 env steps
    assert iterations_per_generation(cfg, PPOSettings(), 500) == 1  # 2048 steps: nearest, and at least 1
    assert iterations_per_generation(cfg, PPOSettings(n_steps=200, n_envs=2), 500) == 4  # exact
    assert iterations_per_generation(cfg, PPOSettings(n_steps=300), 500) == 5  # 5.33 -> 5
    assert iterations_per_generation(cfg, PPOSettings(n_steps=20, steps_per_generation=70), None) == 4  # 3.5
    env_limit = build_config({**TINY, "rollout": {"episodes": 1}})  # 2 * 4 * 1 * 500 (CartPole) = 4000
    assert iterations_per_generation(env_limit, PPOSettings(n_steps=1000), 500) == 4
    with pytest.raises(ConfigError, match="no time limit"):
        iterations_per_generation(env_limit, PPOSettings(), None)


def test_settings_from_a_config_section_and_validation():
    assert ppo_settings(build_config(TINY)) == PPOSettings()  # no 'ppo' section yet: defaults
    fake = types.SimpleNamespace(ppo={"n_epochs": 3, "learning_rate": 1e-3})
    assert ppo_settings(fake) == PPOSettings(n_epochs=3, learning_rate=1e-3)
    with pytest.raises(ConfigError, match="unknown settings"):
        ppo_settings(types.SimpleNamespace(ppo={"n_epoch": 3}))
    with pytest.raises(ConfigError, match="ppo.gamma"):
        PPOSettings(gamma=1.5)


def test_ppo_logs_the_es_columns_on_the_es_test_seeds(tmp_path, monkeypatch):
    from shaped_es.baselines import ppo_state

    seen = []
    orig = ppo_state.DeterministicEpisodes.run

    def spy(self, policy, seeds):
        seen.append(np.array(seeds))
        return orig(self, policy, seeds)

    monkeypatch.setattr(ppo_state.DeterministicEpisodes, "run", spy)
    _, es = _run(tmp_path, "es", "vanilla")
    cfg, store = _run(tmp_path, "ppo", "ppo")
    es_rows, rows = es.read_metrics(), store.read_metrics()
    assert list(rows[0]) == list(es_rows[0])  # same columns, same order
    assert [int(r["generation"]) for r in rows] == [0, 1]
    steps = [int(r["env_steps"]) for r in rows]
    assert steps == [int(rows[0]["gen_env_steps"]), 2 * int(rows[0]["gen_env_steps"])]
    assert int(rows[0]["gen_env_steps"]) == 2 * 4 * 2 * 60  # ES's max per generation = 2 iterations
    for g, s in enumerate(seen):
        np.testing.assert_array_equal(s, seeding.episode_seeds(1, seeding.TEST, g, np.zeros(1), 3)[0])
    for r in rows:
        assert float(r["cpu_time_s"]) > 0 and float(r["update_norm"]) > 0
        assert float(r["test_reward_mean"]) >= 1 and r["train_reward_mean"] != ""
        assert float(r["rollout_time_s"]) < float(r["gen_time_s"])


def test_ppo_resume_continues_from_a_pickle_free_checkpoint(tmp_path):
    from shaped_es.baselines.ppo import train_ppo

    cfg, store = _run(tmp_path, "ppo", "ppo")
    npz = store.ckpt_dir / "gen_000002.npz"
    with zipfile.ZipFile(npz) as z:
        assert all(n.endswith(".npy") for n in z.namelist())
    with np.load(npz, allow_pickle=False) as z:
        assert any(k.startswith("ppo/optim/") for k in z.files) and "ppo/torch_rng" in z.files
        saved = {k: z[k] for k in z.files if k.startswith("ppo/policy/")}
    more = build_config({**cfg.model_dump(mode="json"), "generations": 3})
    rows = train_ppo(more, store, progress=False, settings=FAST)
    assert [r["generation"] for r in rows] == [2]  # only the missing generation ran
    all_rows = store.read_metrics()
    assert [int(r["generation"]) for r in all_rows] == [0, 1, 2]
    assert int(all_rows[2]["env_steps"]) == 3 * int(all_rows[0]["gen_env_steps"])
    assert float(all_rows[2]["cpu_time_s"]) > float(all_rows[1]["cpu_time_s"])
    # a fresh model restored the saved weights before training on: the update starts from them
    from shaped_es.baselines.ppo import PPORun

    run = PPORun(more, store, FAST)
    assert run.restore() and run.c.generation == 3
    with np.load(store.ckpt_dir / "gen_000003.npz", allow_pickle=False) as z:
        for k, v in run.model.policy.state_dict().items():
            np.testing.assert_array_equal(v.numpy(), z["ppo/policy/" + k])
    assert any(not np.array_equal(saved[k], run.model.policy.state_dict()[k[11:]].numpy()) for k in saved)
    run.close()


def test_ppo_refuses_a_checkpoint_of_another_config(tmp_path):
    from shaped_es.baselines.ppo import train_ppo
    from shaped_es.rundir.store import StoreError

    cfg, store = _run(tmp_path, "ppo", "ppo")
    other = build_config({**cfg.model_dump(mode="json"), "generations": 3, "seed": 2})
    with pytest.raises(StoreError, match="different config"):
        train_ppo(other, store, progress=False, settings=FAST)


def test_evaluate_a_ppo_run(tmp_path):
    from shaped_es.trained.evaluate import evaluate_run

    _, store = _run(tmp_path, "ppo", "ppo")
    a = evaluate_run(store.root, episodes=3)
    b = evaluate_run(store.root, episodes=3, which="mean")
    assert a["episodes"] == 3 and np.isfinite(a["reward_mean"]) and a["checkpoint_generations"] == 2
    assert a == evaluate_run(store.root, episodes=3)  # deterministic policy, fixed seeds
    assert np.isfinite(b["reward_mean"])


@pytest.mark.parametrize("bad", [{"generation": "2"}, {"env_steps": -5}, {"cpu_time_s": None},
                                 {"generation": True}])
def test_ppo_refuses_malformed_checkpoint_counters(tmp_path, bad):
    import json

    from shaped_es.baselines.ppo import train_ppo
    from shaped_es.rundir.store import StoreError

    cfg, store = _run(tmp_path, "ppo", "ppo")
    meta_path = max(store.ckpt_dir.glob("gen_*.json"))
    meta = json.loads(meta_path.read_text())
    meta_path.write_text(json.dumps({**meta, **bad}))
    longer = build_config({**cfg.model_dump(mode="json"), "generations": 3})
    with pytest.raises(StoreError, match="malformed"):
        train_ppo(longer, store, progress=False, settings=FAST)
