"""CarNav-v0: Gymnasium contract, determinism, reward terms, episode ends, presets, rendering, solvability."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.envs.carnav.config import make_config
from shaped_es.envs.carnav.core import CarNavCore
from shaped_es.envs.core import BatchCore, get_batch_core, has_waypoint_contract


@pytest.fixture(scope="module")
def env():
    e = gym.make("shaped_es:CarNav-v0", render_mode="rgb_array")
    yield e
    e.close()


def _terms(info):
    return info["reward_waypoint"] + info["reward_step"] + info["reward_collision"]


def test_check_env_and_contract(env):
    check_env(env.unwrapped, skip_render_check=True)
    obs, info = env.reset(seed=1)
    assert obs.shape == (38,) and obs.dtype == np.float32 and env.observation_space.contains(obs)
    assert has_waypoint_contract(info) and info["position"].shape == (2,) and info["waypoint"].shape == (2,)
    core = get_batch_core(env)
    assert isinstance(core, BatchCore) and core is env.unwrapped.batch_core
    assert (core.obs_dim, core.act_dim, core.pos_dim, core.max_steps) == (38, 2, 2, 250)
    # with 1.5 m spacing the local waypoint is the next global waypoint
    np.testing.assert_allclose(info["waypoint"], env.unwrapped.state.route_waypoints(0, 3)[0])
    np.testing.assert_allclose(np.linalg.norm(info["waypoint"] - info["position"]), 1.5, atol=1e-9)
    _, _, _, _, info = env.step(np.zeros(2, np.float32))
    assert has_waypoint_contract(info)


def _play(env, seed, n=120):
    rng = np.random.default_rng(0)
    obs, info = env.reset(seed=seed)
    out = [(obs, info["position"], info["waypoint"], 0.0)]
    for _ in range(n):
        obs, r, term, trunc, info = env.step(rng.uniform(-0.3, 1.0, 2).astype(np.float32))
        assert r == pytest.approx(_terms(info), abs=1e-12)
        out.append((obs, info["position"], info["waypoint"], r))
        if term or trunc:
            break
    return out


def test_same_seed_same_episode(env):
    a, b = _play(env, 7), _play(env, 7)
    c = _play(env, 8)
    assert len(a) == len(b)
    for (o1, p1, w1, r1), (o2, p2, w2, r2) in zip(a, b):
        np.testing.assert_array_equal(o1, o2)
        np.testing.assert_array_equal(p1, p2)
        np.testing.assert_array_equal(w1, w2)
        assert r1 == r2
    assert not np.array_equal(a[0][1], c[0][1])


def test_batch_core_matches_env_and_is_independent_of_batch(env):
    core = env.unwrapped.batch_core
    seeds = np.array([11, 12, 13])
    state, obs, info = core.reset(seeds)
    o1, i1 = env.reset(seed=12)
    np.testing.assert_array_equal(obs[1], o1)
    np.testing.assert_array_equal(info["waypoint"][1], i1["waypoint"])
    act = np.tile(np.array([[0.1, 0.8]], np.float32), (3, 1))
    for _ in range(30):
        state, obs, rew, term, trunc, info = core.step(state, act)
        o1, r1, *_ = env.step(act[1])
        np.testing.assert_array_equal(obs[1], o1)
        assert rew[1] == r1
        np.testing.assert_allclose(rew, _terms(info), atol=1e-12)


def test_collision_ends_episode_with_penalty():
    core = CarNavCore(make_config("default"))
    B = 16
    state, _, _ = core.reset(np.arange(B))
    act = np.tile(np.array([[0.0, 1.0]], np.float32), (B, 1))  # full throttle, straight on: hits a wall
    crashed = np.zeros(B, bool)
    for _ in range(core.max_steps):
        was_done = state.terminated | state.truncated
        state, obs, rew, term, trunc, info = core.step(state, act)
        new = info["collision"]
        assert np.all(term[new]) and np.all(info["reward_collision"][new] == -50.0)
        assert np.all(info["reward_collision"][~new] == 0.0)
        np.testing.assert_allclose(rew, _terms(info), atol=1e-12)
        assert np.all(rew[was_done] == 0.0)  # ended cars are frozen
        crashed |= new
    assert crashed.sum() >= B // 2


def test_truncation_at_max_frames():
    env = gym.make("shaped_es:CarNav-v0", max_steps=20)
    env.reset(seed=3)
    for t in range(20):
        _, r, term, trunc, info = env.step(np.array([0.0, -1.0], np.float32))  # stays put
        assert not term and trunc == (t == 19)
        assert r == pytest.approx(-0.1)


def test_presets_and_overrides():
    paper = gym.make("shaped_es:CarNav-v0", preset="paper").unwrapped
    _, info = paper.reset(seed=0)
    H = info["num_waypoints"]
    assert paper.config.max_steps == 1000 and 800 <= H <= 1200 and paper.config.reach_radius == 0.5
    sparse = gym.make("shaped_es:CarNav-v0", preset="paper", waypoint_spacing=15.0).unwrapped
    _, info_s = sparse.reset(seed=0)
    assert abs(info_s["num_waypoints"] - H / 10) <= 2  # same route, 10x fewer waypoints
    np.testing.assert_allclose(info_s["position"], info["position"])
    # the local waypoint lies on the route between the car and the next (15 m away) global waypoint
    s = sparse.state
    g = s.route_waypoints(0, sparse.config.wp_stride)[0]
    d_local = np.linalg.norm(info_s["waypoint"] - info_s["position"])
    assert 2.5 <= d_local <= 3.5
    assert np.linalg.norm(g - info_s["waypoint"]) < np.linalg.norm(g - info_s["position"])
    with pytest.raises(ValueError, match="unknown option"):
        gym.make("shaped_es:CarNav-v0", speed=3)
    with pytest.raises(ValueError, match="unknown preset"):
        gym.make("shaped_es:CarNav-v0", preset="carla")


def test_render_top_down(env):
    env.reset(seed=4)
    for _ in range(10):
        env.step(np.array([0.0, 1.0], np.float32))
    frame = env.render()
    size = env.unwrapped.config.render_size
    assert frame.shape == (size, size, 3) and frame.dtype == np.uint8
    assert len(np.unique(frame.reshape(-1, 3), axis=0)) >= 6 and frame.std() > 10
    centre = frame[size // 2 - 3: size // 2 + 3, size // 2 - 3: size // 2 + 3]
    assert (centre.min(axis=-1) > 200).any()  # the (white) car sits in the middle of the view


def test_pure_pursuit_solves_random_does_not():
    """The env's waypoint controller (pure pursuit, ``carnav/controller.py``) drives the routes."""
    core = CarNavCore(make_config("default"))
    rng = np.random.default_rng(0)
    fractions, returns = {}, {}
    for name in ("pursuit", "random"):
        state, _, info = core.reset(np.arange(100, 132))
        total, crashed = np.zeros(32), np.zeros(32, bool)
        while not np.all(state.terminated | state.truncated):
            act = core.waypoint_controller(state, None, info) if name == "pursuit" else rng.uniform(-1, 1, (32, 2))
            state, _, rew, _, _, info = core.step(state, act.astype(np.float32))
            total, crashed = total + rew, crashed | info["collision"]
        fractions[name], returns[name] = state.reached / state.num_wp, total
        if name == "pursuit":
            assert not crashed.any()
    assert fractions["pursuit"].mean() > 0.9 and fractions["pursuit"].min() > 0.6
    assert returns["pursuit"].mean() > 150
    assert fractions["random"].mean() < 0.1 and returns["random"].mean() < 0
