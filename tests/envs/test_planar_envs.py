"""The planar suite bodies (PointVel-v0, PointForce-v0, Unicycle-v0, Rover-v0): Gymnasium checks, the contract,
seeded determinism, reward terms, the spatial waypoint rule, the controllers' exact values on fixed states
and their return over the registered threshold."""

import math

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.cli.check_env import FAIL, check_env as shaped_check_env
from shaped_es.envs.core import get_batch_core, has_controller, has_waypoint_contract
from shaped_es.envs.planar.core import PlanarState
from shaped_es.envs.planar.pointforce import PointForceCore
from shaped_es.envs.planar.pointforce import make_config as force_config
from shaped_es.envs.planar.pointvel import PointVelCore
from shaped_es.envs.planar.pointvel import make_config as vel_config
from shaped_es.envs.planar.rover import RoverCore
from shaped_es.envs.planar.rover import make_config as rover_config
from shaped_es.envs.planar.task import advance_index, line_waypoint, num_waypoints, sample_episodes
from shaped_es.envs.planar.unicycle import UnicycleCore
from shaped_es.envs.planar.unicycle import make_config as uni_config

IDS = {"PointVel-v0": 4, "PointForce-v0": 6, "Unicycle-v0": 6, "Rover-v0": 8}  # id -> observation size
LIMITS = {"Rover-v0": (120, 8.0)}  # (time limit, threshold) where not (100, 8.5)
TERMS = ("reward_progress", "reward_step")


def run_controller(core, seeds):
    state, obs, info = core.reset(np.asarray(seeds))
    ret = np.zeros(len(seeds))
    while not state.done.all():
        live = ~state.done
        state, obs, rew, *_, info = core.step(state, core.waypoint_controller(state, obs, info))
        ret += np.where(live, rew, 0.0)
    return ret, state


@pytest.mark.filterwarnings("ignore:.*Box observation space (minimum|maximum) value is")
@pytest.mark.parametrize("env_id", IDS)
def test_check_env_contract_and_spec(env_id):
    env = gym.make(f"shaped_es:{env_id}")
    check_env(env.unwrapped, skip_render_check=True)
    assert (env.spec.max_episode_steps, env.spec.reward_threshold) == LIMITS.get(env_id, (100, 8.5))
    assert not [c for c in shaped_check_env(env_id) if c.status == FAIL]
    obs, info = env.reset(seed=3)
    assert obs.shape == (IDS[env_id],) and obs.dtype == np.float32
    assert has_waypoint_contract(info) and info["position"].shape == info["waypoint"].shape == (2,)
    assert has_controller(env) and get_batch_core(env) is env.unwrapped.batch_core
    for _ in range(5):
        obs, rew, term, trunc, info = env.step(env.action_space.sample())
        assert has_waypoint_contract(info) and info["waypoint"].shape == (2,)
        assert rew == pytest.approx(sum(info[k] for k in TERMS))


@pytest.mark.parametrize("env_id", IDS)
def test_seeded_determinism_and_env_equals_core_row(env_id):
    actions = np.random.default_rng(0).uniform(-1, 1, (40, 2)).astype(np.float32)
    traces = []
    for _ in range(2):
        env = gym.make(f"shaped_es:{env_id}")
        obs, _ = env.reset(seed=11)
        trace = [obs]
        for a in actions:
            obs, rew, *_ = env.step(a)
            trace += [obs, np.array([rew])]
        traces.append(np.concatenate(trace))
    np.testing.assert_array_equal(traces[0], traces[1])
    core = env.unwrapped.batch_core
    state, obs_b, _ = core.reset(np.array([5, 11, 7]))
    assert np.array_equal(obs_b[1], traces[0][: IDS[env_id]])
    other = gym.make(f"shaped_es:{env_id}").reset(seed=12)[0]
    assert not np.array_equal(other, obs_b[1])


def test_the_same_seed_gives_the_same_start_and_goal_on_every_body():
    seeds = np.array([0, 1, 2])
    starts = [c(m()).reset(seeds)[0] for c, m in ((PointVelCore, vel_config), (PointForceCore, force_config),
                                                   (UnicycleCore, uni_config), (RoverCore, rover_config))]
    for s in starts[1:]:
        np.testing.assert_array_equal(s.start, starts[0].start)
        np.testing.assert_array_equal(s.goal, starts[0].goal)
    d0 = np.linalg.norm(starts[0].goal - starts[0].start, axis=1)
    assert ((d0 >= 0.5) & (d0 <= 1.5)).all()


def test_line_waypoints_are_consumed_when_reached_or_passed():
    cfg = vel_config()
    start, goal = np.array([[0.0, 0.0]] * 4), np.array([[0.35, 0.0]] * 4)
    assert num_waypoints(start, goal, 0.1).tolist() == [4] * 4  # 0.1, 0.2, 0.3, 0.35 (the goal)
    np.testing.assert_allclose(line_waypoint(start, goal, np.array([0, 2, 3, 9]), 0.1),
                               [[0.1, 0], [0.3, 0], [0.35, 0], [0.35, 0]])
    pos = np.array([[0.06, 0.0],  # within reach of waypoint 0 (0.1): consumed
                    [0.0, 0.3],  # beside the start, far from the line: nothing
                    [0.25, 0.3],  # projection passed 0.1 and 0.2 (far from the line): two consumed
                    [0.5, 0.0]])  # beyond the goal: all consumed
    assert advance_index(pos, start, goal, np.zeros(4, np.int64), cfg).tolist() == [1, 0, 2, 4]
    assert advance_index(pos[1:2], start[:1], goal[:1], np.array([3]), cfg).tolist() == [3]  # never back


def fixed_state(pos, vel=None, heading=None):
    B = len(pos)
    return PlanarState(pos=np.asarray(pos, float), vel=np.zeros((B, 2)) if vel is None else np.asarray(vel, float),
                       heading=np.zeros(B) if heading is None else np.asarray(heading, float),
                       start=np.zeros((B, 2)), goal=np.ones((B, 2)), index=np.zeros(B, np.int64),
                       steps=np.zeros(B, np.int64), done=np.zeros(B, bool))


def test_pointvel_controller_exact_values():
    core = PointVelCore(vel_config())
    st = fixed_state([[0, 0], [0, 0], [0.5, 0.5]])
    info = {"position": st.pos, "waypoint": np.array([[0.03, -0.04], [0.3, 0.4], [0.5, 0.5]])}
    a = core.waypoint_controller(st, None, info)
    assert a.dtype == np.float32
    np.testing.assert_allclose(a, [[0.6, -0.8], [0.6, 0.8], [0, 0]], atol=1e-7)  # reach it; full speed
    st2, *_ = core.step(st, a)
    np.testing.assert_allclose(st2.pos[0], [0.03, -0.04])  # lands on the waypoint


def test_pointforce_controller_exact_values():
    core = PointForceCore(force_config())
    st = fixed_state([[0, 0], [0, 0]], vel=[[0, 0], [0.5, 0]])
    info = {"position": st.pos, "waypoint": np.array([[1.0, 0.0], [0.0, 1.0]])}
    a = core.waypoint_controller(st, None, info)
    np.testing.assert_allclose(a[0], [1, 0], atol=1e-7)  # at rest: full force toward it
    g = 4 * (np.array([0, 0.5]) - np.array([0.5, 0])) + np.array([0, 1])  # moving across: brake + turn
    np.testing.assert_allclose(a[1], g / np.linalg.norm(g), atol=1e-6)
    st2, *_ = core.step(st, a)
    np.testing.assert_allclose(st2.vel[0], [0.05, 0])  # v += dt * (accel * a - damping * v)
    np.testing.assert_allclose(st2.pos[0], [0.005, 0])


def test_unicycle_controller_exact_values():
    core = UnicycleCore(uni_config())
    st = fixed_state([[0, 0]] * 3, heading=[0, 0, math.pi / 2])
    info = {"position": st.pos, "waypoint": np.array([[0.2, 0.0], [0.0, -0.2], [0.02, 0.0]])}
    a = core.waypoint_controller(st, None, info)
    np.testing.assert_allclose(a[0], [1, 0], atol=1e-7)  # straight ahead: full speed, no turn
    assert a[1, 1] == -1 and a[1, 0] == pytest.approx(math.cos(math.pi / 2 - 0.5))  # right: turn, creep
    assert a[2, 1] == -1 and a[2, 0] == pytest.approx(0.4 * math.cos(math.pi / 2 - 0.5))  # near: slower
    st2, *_ = core.step(st, a)
    assert st2.heading[1] == pytest.approx(-0.5)
    np.testing.assert_allclose(st2.pos[0], [0.05, 0])


def test_rover_dynamics_and_controller_exact_values():
    core = RoverCore(rover_config())
    st = fixed_state([[0, 0]] * 3, vel=[[0, 0], [0.5, 0], [0.5, 5.0]], heading=[0, 0, 0])
    st2, *_ = core.step(st, np.array([[1, 1], [0, 0], [0, -1]], np.float32))
    # v += dt * (accel * a0 - damping * v); w += dt * (yaw_accel * a1 - yaw_damping * w); heading += dt * w
    np.testing.assert_allclose(st2.vel, [[0.05, 1.0], [0.45, 0], [0.45, 3.0]])
    np.testing.assert_allclose(st2.heading, [0.1, 0, 0.3])
    np.testing.assert_allclose(st2.pos[0], 0.005 * np.array([math.cos(0.1), math.sin(0.1)]))
    np.testing.assert_allclose(core.observe(st2)[2, 4:6], [0.45, 3.0], rtol=1e-6)  # speed, yaw rate
    info = {"position": st.pos, "waypoint": np.array([[1.0, 0.0], [0.0, 1.0], [1.0, 0.0]]),
            "goal": np.array([[2.0, 0.0]] * 3)}
    a = core.waypoint_controller(st, None, info)
    np.testing.assert_allclose(a[0], [1, 0], atol=1e-7)  # at rest, aligned: full thrust, no torque
    np.testing.assert_allclose(a[1], [-1, 1])  # moving, the waypoint to the left: brake and turn left
    np.testing.assert_allclose(a[2], [1, -1])  # spinning left, the waypoint ahead: thrust, torque against it
    st = fixed_state([[0, 0]], vel=[[0.5, 0]])  # cruising, aligned: thrust holds the speed against damping
    a = core.waypoint_controller(st, None, {"position": st.pos, "waypoint": np.array([[1.0, 0]]),
                                            "goal": np.array([[2.0, 0]])})
    np.testing.assert_allclose(a[0], [1, 0], atol=1e-7)


@pytest.mark.parametrize("core_cls,make", [(PointVelCore, vel_config), (PointForceCore, force_config),
                                           (UnicycleCore, uni_config), (RoverCore, rover_config)])
def test_the_controller_clears_the_threshold_on_20_episodes(core_cls, make):
    core = core_cls(make())
    limit, threshold = LIMITS.get(f"{core_cls.__name__[:-4]}-v0", (100, 8.5))
    ret, state = run_controller(core, np.arange(20))
    assert ret.mean() > threshold + 0.5 and ret.min() > threshold  # the registered threshold, with its margin
    assert (state.steps < limit).all()  # every episode ended at the goal


def test_ended_episodes_stay_unchanged():
    core = PointVelCore(vel_config(max_steps=3))
    state, *_ = core.reset(np.array([0, 1]))
    for _ in range(3):
        state, *_ = core.step(state, np.ones((2, 2), np.float32))
    assert state.done.all()
    after, _, rew, *_ = core.step(state, np.ones((2, 2), np.float32))
    np.testing.assert_array_equal(after.pos, state.pos)
    assert (rew == 0).all() and (after.steps == 3).all()


def test_envs_lists_the_presets_from_the_env_module():
    from shaped_es.cli.describe_env import _presets

    assert _presets("PointVel-v0") == ["default"] and _presets("CarNav-v0") == ["default", "paper"]
    assert _presets("ReacherWay-v0") == ["default"] and _presets("CartPole-v1") == []
