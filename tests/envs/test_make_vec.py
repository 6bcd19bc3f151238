"""``gymnasium.make_vec`` on the built-in envs: the batched core behind a Gymnasium 1.x ``VectorEnv``
(shapes, seeding, NEXT_STEP autoreset), equal step for step to ``SyncVectorEnv`` over ``gymnasium.make``."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.vector import AutoresetMode

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.envs.vector import BatchCoreVectorEnv

ENVS = {"CarNav-v0": (38, 2, {"max_steps": 30}), "UR5Reach-v0": (13, 5, {"max_steps": 20})}


def _actions(env, steps, seed=0):
    rng = np.random.default_rng(seed)
    return [rng.uniform(-1, 1, env.action_space.shape).astype(np.float32) for _ in range(steps)]


def _roll(env, seed, actions):
    obs, _ = env.reset(seed=seed)
    out = [obs]
    for a in actions:
        obs, rew, term, trunc, _ = env.step(a)
        out += [obs, rew, term, trunc]
    return out


@pytest.mark.parametrize("env_id", list(ENVS))
def test_make_vec_shapes_and_seeding(env_id):
    obs_dim, act_dim, kw = ENVS[env_id]
    env = gym.make_vec(f"shaped_es:{env_id}", num_envs=8, vectorization_mode="vector_entry_point", **kw)
    assert isinstance(env.unwrapped, BatchCoreVectorEnv) and env.num_envs == 8
    assert env.metadata["autoreset_mode"] == AutoresetMode.NEXT_STEP
    assert env.single_observation_space.shape == (obs_dim,) and env.observation_space.shape == (8, obs_dim)
    assert env.single_action_space.shape == (act_dim,) and env.action_space.shape == (8, act_dim)
    obs, info = env.reset(seed=3)
    assert obs.shape == (8, obs_dim) and obs.dtype == np.float32
    assert info["position"].shape[0] == 8 and info["_position"].all()
    obs, rew, term, trunc, info = env.step(env.action_space.sample())
    assert obs.shape == (8, obs_dim) and rew.shape == term.shape == trunc.shape == (8,)
    assert rew.dtype == np.float64 and term.dtype == trunc.dtype == bool
    acts = _actions(env, 25)
    a, b = _roll(env, 11, acts), _roll(env, 11, acts)
    assert all(np.array_equal(x, y) for x, y in zip(a, b))  # same seed, same actions: same rollout
    c = _roll(env, 12, acts)
    assert not np.array_equal(a[0], c[0])
    # sub-env i plays the episode a single env plays with seed + i
    single = gym.make(f"shaped_es:{env_id}", **kw)
    np.testing.assert_array_equal(a[0][5], single.reset(seed=16)[0])
    env.close()


@pytest.mark.parametrize("env_id", list(ENVS))
def test_make_vec_equals_sync_vector_env_through_autoresets(env_id):
    _, _, kw = ENVS[env_id]  # short episodes: 70 steps cross two or three autoresets
    fast = gym.make_vec(f"shaped_es:{env_id}", num_envs=4, vectorization_mode="vector_entry_point", **kw)
    sync = gym.make_vec(f"shaped_es:{env_id}", num_envs=4, vectorization_mode="sync", **kw)
    o1, _ = fast.reset(seed=5)
    o2, _ = sync.reset(seed=5)
    np.testing.assert_array_equal(o1, o2)
    ended = 0
    for a in _actions(fast, 70, seed=1):
        r1, r2 = fast.step(a), sync.step(a)
        for x, y in zip(r1[:4], r2[:4]):
            np.testing.assert_allclose(x, y, rtol=1e-6, atol=1e-6)
        for k, v in r2[4].items():
            np.testing.assert_allclose(np.asarray(r1[4][k], float), np.asarray(v, float), rtol=1e-6, atol=1e-6)
        ended += int((r1[2] | r1[3]).sum())
    assert ended >= 8  # autoreset was exercised


def test_reset_mask_and_max_episode_steps():
    env = gym.make_vec("shaped_es:CarNav-v0", num_envs=3, vectorization_mode="vector_entry_point",
                       max_episode_steps=4)
    obs0, _ = env.reset(seed=0)
    zero = np.zeros(env.action_space.shape, np.float32)
    for _ in range(3):
        obs, _, _, trunc, _ = env.step(zero)
        assert not trunc.any()
    obs, _, _, trunc, _ = env.step(zero)
    assert trunc.all()  # the make_vec limit (the core's own is 250)
    obs, rew, term, trunc, _ = env.step(zero)  # NEXT_STEP: the reset step
    assert not (term | trunc).any() and (rew == 0).all()
    moved, _, _, _, _ = env.step(zero)
    again, _ = env.reset(seed=7, options={"reset_mask": np.array([False, True, False])})
    np.testing.assert_array_equal(again[[0, 2]], moved[[0, 2]])
    np.testing.assert_array_equal(again[1], gym.make("shaped_es:CarNav-v0").reset(seed=8)[0])
