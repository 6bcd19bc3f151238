"""UR5Reach-v0: Gymnasium checks, the env contract, determinism, reward terms, waypoint rule, solvability."""

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shaped_es  # noqa: F401 - registers the env
from shaped_es.envs.core import BatchCore, get_batch_core, has_waypoint_contract
from shaped_es.envs.ur5.config import make_config
from shaped_es.envs.ur5.controller import waypoint_controller
from shaped_es.envs.ur5.core import UR5Core
from shaped_es.envs.ur5.env import UR5ReachEnv

TERMS = ("reward_waypoint", "reward_step", "reward_collision")


def run_core(core, seeds, policy):
    """Roll every seed to the end; returns (returns (B,), per-step (reward, info, done-before) list)."""
    state, obs, info = core.reset(np.asarray(seeds))
    ret, log = np.zeros(len(seeds)), []
    while not state.done.all():
        live = ~state.done
        state, obs, rew, term, trunc, info = core.step(state, policy(obs, info))
        ret += np.where(live, rew, 0.0)
        log.append((rew, info, live, term, trunc, state))
    return ret, log


@pytest.mark.filterwarnings("ignore:.*Box observation space (minimum|maximum) value is")
def test_check_env_and_contract():
    env = gym.make("shaped_es:UR5Reach-v0")
    check_env(env.unwrapped, skip_render_check=True)
    obs, info = env.reset(seed=1)
    assert obs.shape == (13,) and obs.dtype == np.float32
    assert has_waypoint_contract(info) and info["position"].shape == (3,) and info["waypoint"].shape == (3,)
    for _ in range(3):
        obs, rew, term, trunc, info = env.step(env.action_space.sample())
        assert has_waypoint_contract(info) and info["waypoint"].shape == (3,)
        assert rew == pytest.approx(sum(info[k] for k in TERMS))
    core = get_batch_core(env)
    assert isinstance(core, BatchCore) and core is env.unwrapped.batch_core
    assert (core.obs_dim, core.act_dim, core.pos_dim, core.max_steps) == (13, 5, 3, 100)
    np.testing.assert_allclose(obs[10:], info["target"] - info["position"], atol=1e-6)  # target - effector


def test_make_kwargs_override_the_preset():
    env = gym.make("shaped_es:UR5Reach-v0", preset="paper", reach_radius=0.05, max_steps=20)
    cfg = env.unwrapped.config
    assert (cfg.reach_radius, cfg.max_steps, cfg.target_azimuth) == (0.05, 20, (-np.pi, np.pi))
    with pytest.raises(ValueError, match="unknown option"):
        UR5ReachEnv(bogus=3)


def test_seeded_determinism_and_env_equals_core_row():
    actions = np.random.default_rng(0).uniform(-0.4, 0.4, (30, 5)).astype(np.float32)
    traces = []
    for _ in range(2):
        env = UR5ReachEnv()
        obs, _ = env.reset(seed=11)
        trace = [obs]
        for a in actions:
            obs, rew, term, trunc, info = env.step(a)
            trace += [obs, [rew], info["position"], info["waypoint"]]
        traces.append(np.concatenate([np.ravel(x) for x in trace]))
    np.testing.assert_array_equal(traces[0], traces[1])
    core = UR5Core(make_config())  # the same episode as row 1 of a batch
    state, obs, _ = core.reset(np.array([5, 11, 7]))
    ref = [obs[1]]
    for a in actions:
        state, obs, rew, _, _, info = core.step(state, np.stack([a, a, -a]))
        ref += [obs[1], [rew[1]], info["position"][1], info["waypoint"][1]]
    np.testing.assert_array_equal(traces[0], np.concatenate([np.ravel(x) for x in ref]))


def test_step_is_pure_state_in_state_out():
    core = UR5Core(make_config())
    state, _, _ = core.reset(np.arange(4))
    snapshot = {k: v.copy() for k, v in state.__dict__.items()}
    act = np.random.default_rng(3).uniform(-1, 1, (4, 5))
    first = core.step(state, act)
    core.step(first[0], -act)  # unrelated call in between reuses the same scratch Batch
    second = core.step(state, act)
    for a, b in zip(first[1:5], second[1:5]):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(first[0].qpos, second[0].qpos)
    for k, v in snapshot.items():
        np.testing.assert_array_equal(getattr(state, k), v)


def test_reward_terms_sum_and_collision_ends_episode_with_penalty():
    core = UR5Core(make_config())
    rng = np.random.default_rng(4)
    _, log = run_core(core, np.arange(32), lambda o, i: rng.uniform(-1, 1, (32, 5)))
    collided = False
    for rew, info, live, term, trunc, state in log:
        np.testing.assert_allclose(rew, sum(info[k] for k in TERMS))
        assert set(np.unique(info["reward_step"][live])) == {-0.1}
        np.testing.assert_array_equal(term, info["collision"])
        assert (info["reward_collision"][term] == -50.0).all() and state.done[term].all()
        collided |= term.any()
    assert collided  # full random torques hit the ground or the arm itself


def test_waypoint_rule_one_per_step_when_reached():
    core = UR5Core(make_config())
    cfg = core.config
    state, _, info = core.reset(np.arange(8))
    for _ in range(cfg.max_steps):
        wp, before = info["waypoint"], state.index
        state, _, rew, term, trunc, info = core.step(state, np.zeros((8, 5)))  # stand still
        reached = np.linalg.norm(info["position"] - wp, axis=1) < cfg.reach_radius
        np.testing.assert_array_equal(state.index, before + reached)
        pay = np.where(reached, cfg.max_steps / cfg.num_waypoints, 0.0)  # +M/H per waypoint reached
        np.testing.assert_allclose(info["reward_waypoint"], pay)
    assert trunc.all() and not term.any() and (state.steps == cfg.max_steps).all()
    assert (state.index < 12).all() and (state.index >= 3).all()  # only the waypoints near the start pay


def test_hand_written_controller_beats_random_policy():
    core = UR5Core(make_config())
    seeds = np.arange(100, 116)
    expert = lambda o, i: waypoint_controller(core.config, o, i["position"], i["waypoint"])  # noqa: E731
    ctrl, _ = run_core(core, seeds, expert)
    rng = np.random.default_rng(5)
    rand, _ = run_core(core, seeds, lambda o, i: rng.uniform(-1, 1, (16, 5)))
    assert ctrl.mean() > 80.0  # max is 100 * M/H - 100 * 0.1 = 90
    assert rand.mean() < 0.0


def test_the_controller_hook_is_the_hand_written_controller_on_core_and_env():
    """The env's waypoint_controller hook (the ``controller`` label source): on the core, on the
    Gymnasium env's single copy, and ``controller.waypoint_controller`` on the same obs and info."""
    from shaped_es.envs.core import has_controller

    env = gym.make("shaped_es:UR5Reach-v0")
    assert has_controller(env)
    core = env.unwrapped.batch_core
    obs, info = env.reset(seed=5)
    state, obs_b, info_b = core.reset(np.array([5]))
    for _ in range(4):
        a = env.unwrapped.waypoint_controller(obs, info)
        ab = core.waypoint_controller(state, obs_b, info_b)
        np.testing.assert_array_equal(a, ab[0])
        np.testing.assert_array_equal(ab, waypoint_controller(core.config, obs_b, info_b["position"],
                                                              info_b["waypoint"]))
        assert ab.shape == (1, 5) and np.abs(ab).max() <= 1.0
        obs, *_, info = env.step(a)
        state, obs_b, _, _, _, info_b = core.step(state, ab)


def test_ended_episodes_are_not_stepped_and_stay_unchanged():
    core = UR5Core(make_config())
    state, _, _ = core.reset(np.arange(3))
    state = type(state)(**{**state.__dict__, "done": np.array([False, True, False])})
    act = np.full((3, 5), 0.8)
    new, obs, rew, term, trunc, info = core.step(state, act)
    for name in ("qpos", "qvel", "effector", "index", "steps"):
        np.testing.assert_array_equal(getattr(new, name)[1], getattr(state, name)[1])
    assert rew[1] == 0.0 and not term[1] and not trunc[1]
    assert not np.allclose(new.qpos[0], state.qpos[0])  # the live rows moved
    again = core.step(state, act)
    np.testing.assert_array_equal(obs, again[1])


def test_results_do_not_depend_on_thread_count():
    act = np.random.default_rng(6).uniform(-1, 1, (20, 8, 5))
    outs = []
    for threads in (1, 2):
        core = UR5Core(make_config(threads=threads))
        state, obs, _ = core.reset(np.arange(8))
        trace = [obs]
        for a in act:
            state, obs, rew, *_ = core.step(state, a)
            trace += [obs, rew[:, None]]
        outs.append(np.concatenate(trace, axis=1))
    np.testing.assert_array_equal(outs[0], outs[1])


@pytest.mark.filterwarnings("ignore:.*Box observation space (minimum|maximum) value is")
def test_observe_phase_appends_the_episodes_phase_and_changes_nothing_else():
    """observe_phase (a diagnostic of the timed waypoint path): the observation gains the column
    steps / max_steps; dynamics, rewards and the first 13 columns are the default env's."""
    plain, phased = UR5Core(make_config()), UR5Core(make_config(observe_phase=True))
    assert (plain.obs_dim, phased.obs_dim) == (13, 14)
    env = gym.make("UR5Reach-v0", observe_phase=True)
    assert env.observation_space.shape == (14,)
    check_env(env.unwrapped, skip_render_check=True)
    rng = np.random.default_rng(0)
    s0, o0, _ = plain.reset(np.array([3, 4]))
    s1, o1, _ = phased.reset(np.array([3, 4]))
    np.testing.assert_array_equal(o1[:, :13], o0)
    np.testing.assert_array_equal(o1[:, 13], 0.0)
    for t in range(1, 6):
        a = rng.uniform(-1, 1, (2, 5))
        s0, o0, r0, *_ = plain.step(s0, a)
        s1, o1, r1, *_ = phased.step(s1, a)
        np.testing.assert_array_equal(o1[:, :13], o0)
        np.testing.assert_array_equal(r1, r0)
        np.testing.assert_allclose(o1[:, 13], t / plain.config.max_steps)
