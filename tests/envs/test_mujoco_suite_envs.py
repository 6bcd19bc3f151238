"""ReacherWay-v0 and SwimmerWay-v0: Gymnasium's Reacher-v5 / Swimmer-v5 episodes reproduced by batched
cores (same seed and actions -> same observations and rewards), the contract, seeding, reward terms,
the controllers' exact values on fixed states and their return over the registered threshold."""

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.cli.check_env import FAIL, check_env as shaped_check_env
from shaped_es.envs.core import get_batch_core, has_controller, has_waypoint_contract
from shaped_es.envs.reacher import ReacherWayCore, jacobian, resolved_rate, timed_waypoint
from shaped_es.envs.swimmer import SwimmerWayCore

CASES = {  # id: (Gymnasium's env, obs dim, steps, reward terms, threshold)
    "ReacherWay-v0": ("Reacher-v5", 10, 50, ("reward_dist", "reward_ctrl"), -6.5),
    "SwimmerWay-v0": ("Swimmer-v5", 8, 100, ("reward_forward", "reward_ctrl"), 30.0),
}


@pytest.fixture(autouse=True)
def _cwd(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo may log model warnings to ./MUJOCO_LOG.TXT


@pytest.mark.filterwarnings("ignore:.*Box observation space (minimum|maximum) value is")
@pytest.mark.parametrize("env_id", CASES)
def test_check_env_contract_and_spec(env_id):
    _, obs_dim, steps, terms, threshold = CASES[env_id]
    env = gym.make(f"shaped_es:{env_id}")
    check_env(env.unwrapped, skip_render_check=True)
    assert env.spec.max_episode_steps == steps and env.spec.reward_threshold == threshold
    assert not [c for c in shaped_check_env(env_id) if c.status == FAIL]
    obs, info = env.reset(seed=2)
    assert obs.shape == (obs_dim,) and has_waypoint_contract(info)
    assert info["position"].shape == info["waypoint"].shape == (2,)
    assert has_controller(env) and get_batch_core(env) is env.unwrapped.batch_core
    for _ in range(4):
        obs, rew, term, trunc, info = env.step(env.action_space.sample())
        assert rew == pytest.approx(sum(info[k] for k in terms))


@pytest.mark.parametrize("env_id", CASES)
def test_episodes_are_gymnasiums_own(env_id):
    theirs, _, steps, _, _ = CASES[env_id]
    ref, mine = gym.make(theirs).unwrapped, gym.make(f"shaped_es:{env_id}")
    rng = np.random.default_rng(0)
    for seed in (0, 7):
        o1, _ = ref.reset(seed=seed)
        o2, _ = mine.reset(seed=seed)
        np.testing.assert_allclose(o2, o1, atol=1e-6)
        for _ in range(min(steps, 60)):
            a = rng.uniform(-1, 1, 2).astype(np.float32)
            o1, r1, *_ = ref.step(a)
            o2, r2, *_ = mine.step(a)
            np.testing.assert_allclose(o2, o1, atol=1e-5)
            assert r2 == pytest.approx(r1, abs=1e-6)  # float32 actions squared in float32 there


@pytest.mark.parametrize("core_cls", [ReacherWayCore, SwimmerWayCore])
def test_core_rows_are_independent_and_step_is_pure(core_cls):
    core = core_cls()
    s3, obs3, _ = core.reset(np.array([4, 5, 6]))
    s1, obs1, _ = core.reset(np.array([5]))
    np.testing.assert_array_equal(obs3[1], obs1[0])
    a = np.tile(np.array([[0.3, -0.7]], np.float32), (3, 1))
    before = s3.qpos.copy()
    n3, o3, r3, *_ = core.step(s3, a)
    n1, o1, r1, *_ = core.step(s1, a[:1])
    np.testing.assert_array_equal(s3.qpos, before)  # state in, state out
    np.testing.assert_allclose(o3[1], o1[0], atol=1e-6)
    assert r3[1] == pytest.approx(r1[0])


def test_reacher_timed_waypoints_walk_the_line_in_reach_steps():
    core = ReacherWayCore()
    state, obs, info = core.reset(np.array([1]))
    start, target = state.start[0], state.target[0, :2]
    np.testing.assert_allclose(info["waypoint"][0], start + (target - start) / 15)
    for t in range(1, 20):
        state, obs, _, _, _, info = core.step(state, np.zeros((1, 2), np.float32))
        frac = min(1.0, (t + 1) / 15)
        np.testing.assert_allclose(info["waypoint"][0], start + (target - start) * frac)
    np.testing.assert_allclose(timed_waypoint(np.zeros(2), np.ones(2), 30, 15), [1, 1])


def test_reacher_controller_exact_values():
    # arm bent 90 deg at the elbow, at rest: fingertip (0.1, 0.11)
    q = np.array([[0.0, math.pi / 2]])
    obs = np.zeros((1, 10))
    obs[0, :2], obs[0, 2:4] = np.cos(q[0]), np.sin(q[0])
    J = jacobian(q)[0]
    np.testing.assert_allclose(J, [[-0.11, -0.11], [0.1, 0.0]], atol=1e-12)
    tip, wp = np.array([[0.1, 0.11]]), np.array([[0.1, 0.12]])
    v = 20.0 * (wp - tip)[0]
    qd = J.T @ np.linalg.solve(J @ J.T + 0.15**2 * np.eye(2), v)
    np.testing.assert_allclose(resolved_rate(obs, tip, wp)[0], np.clip(0.1 * qd, -1, 1), rtol=1e-6)
    obs[0, 6:8] = [50.0, -50.0]  # spinning fast: full torque against it
    np.testing.assert_array_equal(resolved_rate(obs, tip, tip)[0], [-1.0, 1.0])


def test_swimmer_controller_is_the_gait_at_the_episodes_step():
    core = SwimmerWayCore()
    state, obs, info = core.reset(np.array([0, 1]))
    np.testing.assert_allclose(core.waypoint_controller(state, obs, info), [[0, math.sin(-math.pi / 3)]] * 2,
                               atol=1e-7)
    for _ in range(5):
        state, obs, _, _, _, info = core.step(state, np.zeros((2, 2), np.float32))
    w = 2 * math.pi * 0.8 * 0.04 * 5
    np.testing.assert_allclose(core.waypoint_controller(state, obs, info)[0], [math.sin(w), math.sin(w - math.pi / 3)],
                               atol=1e-6)
    np.testing.assert_allclose(info["waypoint"][0], state.start[0] + [0.2 * 0.04 * 6, 0.0])


def controller_returns(core, n=20):
    state, obs, info = core.reset(np.arange(n))
    ret = np.zeros(n)
    while not state.done.all():
        live = ~state.done
        state, obs, rew, *_, info = core.step(state, core.waypoint_controller(state, obs, info))
        ret += np.where(live, rew, 0.0)
    return ret


def test_the_reacher_controller_clears_the_threshold_on_20_episodes():
    ret = controller_returns(ReacherWayCore())
    assert ret.mean() == pytest.approx(-5.86, abs=0.02) and ret.mean() > gym.spec("ReacherWay-v0").reward_threshold


def test_the_swimmer_gait_swims_but_its_threshold_is_set_above_it():
    ret = controller_returns(SwimmerWayCore())  # the docstring's numbers: the threshold is not the gait's
    assert ret.mean() == pytest.approx(19.0, abs=0.05) and ret.min() > 17.0
    assert ret.mean() < gym.spec("SwimmerWay-v0").reward_threshold
