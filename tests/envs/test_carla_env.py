"""CarlaNav-v0 against the in-process TEST DOUBLE of the carla client (``carla_double.py``): the call
order (settings, a tick per step, listen/stop/destroy), clean-up on close and on error, faults that
raise instead of hanging, Gymnasium's env checker, and the rollout layer's serial episodes."""

import sys

import carla_double as cd
import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import shaped_es  # noqa: F401 - registers the envs
from shaped_es.envs.carla import connection
from shaped_es.envs.carla.connection import CarlaError, CarlaServerLost
from shaped_es.executors.base import WORKER_INDEX_ENV
from shaped_es.rollout import EnvError, EnvSpecError, RolloutTask, make_env, run_task
from shaped_es.policies import MLPSpec

FAST = {"route_length": (20.0, 400.0), "sensor_timeout_s": 0.2}
AHEAD = (20.0, 0.0, 0.5)  # a post on lane 0, 10 m ahead of spawn point 0


@pytest.fixture
def server(monkeypatch):
    monkeypatch.setitem(sys.modules, "carla", cd.module())
    for var in (WORKER_INDEX_ENV, "SHAPED_ES_CARLA_HOST", "SHAPED_ES_CARLA_PORT"):
        monkeypatch.delenv(var, raising=False)
    cd.SERVERS.clear()
    srv = cd.SERVERS["localhost:2000"] = cd.FakeServer()
    yield srv
    connection.close_all()
    cd.SERVERS.clear()


def only_spawn_zero(srv):
    """Block every spawn point but the first (lane 0 at x = 10 heading east), so any seed starts there."""
    srv.blocked = [(t.location.x, t.location.y) for t in srv.map.get_spawn_points()[1:]]


def test_without_the_package_one_line_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "carla", None)  # import carla -> ImportError
    with pytest.raises(EnvSpecError) as err:
        make_env("CarlaNav-v0")
    msg = str(err.value)
    assert "\n" not in msg and msg.endswith("pip install -e '.[carla]'") and "CarlaNav-v0" in msg


def test_no_server_is_one_line_naming_host_and_port(server):
    env = gym.make("CarlaNav-v0", port=2100)  # making the env needs no server
    with pytest.raises(CarlaServerLost, match=r"no CARLA server answers at localhost:2100 within 10 s") as err:
        env.reset(seed=0)
    assert err.value.worker_fault and "\n" not in str(err.value)
    env.close()


def test_call_order_and_clean_up_on_close(server):
    only_spawn_zero(server)
    env = gym.make("CarlaNav-v0", **FAST)
    obs, info = env.reset(seed=3)
    log = server.log
    sync = log.index("apply_settings sync=True dt=0.1 no_render=True")
    assert log.index("get_settings") < sync < log.index("try_spawn vehicle.tesla.model3")
    assert log.index("listen sensor.lidar.ray_cast") < log.index("tick")
    assert log.count("tick") == 5  # settle_ticks, braked
    np.testing.assert_allclose(info["position"], [10.0, 0.0])
    assert obs[6] == 1.0 and obs[37] < 1.0  # own body dropped; the post 15 m ahead, 4 m right: beam 31
    n = len(log)
    for _ in range(3):
        env.step(np.array([0.0, 1.0], np.float32))
    assert log[n:] == ["apply_control", "tick"] * 3  # one control and one tick per step
    env.close()
    tail = log[-6:]
    assert tail[:2] == ["stop sensor.lidar.ray_cast", "stop sensor.other.collision"]
    assert sorted(tail[2:5]) == ["destroy sensor.lidar.ray_cast", "destroy sensor.other.collision",
                                 "destroy vehicle.tesla.model3"]
    assert tail[5] == "apply_settings sync=False dt=None no_render=False"  # the server's own settings back
    assert server.actors == {} and server.settings == cd.WorldSettings(False, False, None)


def test_reset_replaces_the_actors(server):
    env = gym.make("CarlaNav-v0", **FAST)
    env.reset(seed=0)
    first = set(server.actors)
    env.reset(seed=1)
    assert len(server.actors) == 3 and not first & set(server.actors)
    env.close()


def test_lidar_collision_reward_and_termination(server):
    only_spawn_zero(server)
    server.posts = [AHEAD]
    env = gym.make("CarlaNav-v0", **FAST)
    obs, info = env.reset(seed=0)
    assert obs[6] == pytest.approx(9.5 / 20.0)  # the post's surface, 9.5 m ahead
    assert np.all(obs[7:] == 1.0)
    for _ in range(200):
        obs, r, term, trunc, info = env.step(np.array([0.0, 1.0], np.float32))
        if term or trunc:
            break
    assert term and info["collision"] and info["reward_collision"] == -50.0
    assert r == pytest.approx(info["reward_waypoint"] - 0.1 - 50.0)
    assert info["waypoints_reached"] > 0  # it drove along the route until it hit the post
    env.close()


def test_same_seed_same_episode(server):
    env = gym.make("CarlaNav-v0", **FAST)
    runs = []
    for _ in range(2):
        obs, _ = env.reset(seed=7)
        seq = [obs]
        for t in range(20):
            seq.append(env.step(np.array([0.3 * np.sin(t), 0.8], np.float32))[0])
        runs.append(np.stack(seq))
    np.testing.assert_array_equal(*runs)
    env.close()


def test_gymnasium_env_checker_passes(server):
    env = gym.make("CarlaNav-v0", **FAST)
    check_env(env.unwrapped, skip_render_check=True)
    env.close()


@pytest.mark.parametrize("fault", ["dead", "lidar_silent"])
def test_a_server_that_dies_mid_episode_raises_from_step(server, fault):
    env = gym.make("CarlaNav-v0", **FAST)
    env.reset(seed=0)
    env.step(np.zeros(2, np.float32))
    setattr(server, fault, True)
    with pytest.raises(CarlaServerLost, match="localhost:2000") as err:
        env.step(np.zeros(2, np.float32))
    assert err.value.worker_fault
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(np.zeros(2, np.float32))
    if fault == "lidar_silent":  # the server still answers: actors destroyed, settings restored
        assert server.actors == {} and not server.settings.synchronous_mode
    setattr(server, fault, False)
    env.reset(seed=0)  # a server that answers again: the env reconnects
    env.close()


def test_another_client_ticking_the_server_is_refused(server):
    env = gym.make("CarlaNav-v0", **FAST)
    env.reset(seed=0)
    server.rogue_ticks = 1
    with pytest.raises(CarlaError, match="another client ticks the CARLA server at localhost:2000"):
        env.step(np.zeros(2, np.float32))
    assert server.actors == {} and not server.settings.synchronous_mode  # cleaned up after the error
    env.close()


def test_version_mismatch_town_load_and_stale_actors(server):
    server.version = "0.9.15"
    env = gym.make("CarlaNav-v0", **FAST)
    with pytest.raises(CarlaError, match="runs 0.9.15 but the client is 0.9.16.*pip install carla==0.9.15"):
        env.reset(seed=0)
    server.version = "0.9.16-3-gdeadbeef"
    server.map.name = "Carla/Maps/Town01"
    stale = cd.World(server).try_spawn_actor(cd.ActorBlueprint("vehicle.tesla.model3"), cd.Transform())
    stale.attributes["role_name"] = "shaped_es"  # left behind by a killed worker
    env.reset(seed=0)
    assert server.loaded == ["Town07"] and stale.id not in server.actors
    env.close()


def test_worker_index_picks_the_port(server, monkeypatch):
    other = cd.SERVERS["localhost:2006"] = cd.FakeServer("localhost:2006")
    monkeypatch.setenv(WORKER_INDEX_ENV, "2")
    env = gym.make("CarlaNav-v0", **FAST)
    env.reset(seed=0)
    assert len(other.actors) == 3 and server.log == []
    env.close()


def test_two_envs_of_one_process_take_turns(server):
    a, b = gym.make("CarlaNav-v0", **FAST), gym.make("CarlaNav-v0", **FAST)
    a.reset(seed=0)
    b.reset(seed=1)  # takes the world: a's episode ends
    assert len(server.actors) == 3
    with pytest.raises(RuntimeError, match="another CarlaNav-v0 env of this process"):
        a.step(np.zeros(2, np.float32))
    b.close()
    assert server.settings.synchronous_mode  # a still holds the session
    a.close()
    assert not server.settings.synchronous_mode and server.actors == {}


def test_rollout_runs_the_episodes_one_at_a_time(server):
    spec = MLPSpec(38, 2, (4,))
    rng = np.random.default_rng(0)
    params = rng.normal(0, 0.5, (2, spec.num_params)).astype(np.float32)
    seeds = np.array([[11, 12], [13, 14]])
    task = RolloutTask("CarlaNav-v0", {**FAST, "max_steps": 15}, spec, params, np.array([4, 5]), seeds,
                       generation=2, record=True)
    out = run_task(task)
    assert out.returns.shape == (2, 2) and (out.lengths == 15).all()
    for i in range(2):
        for e in range(2):
            one = run_task(RolloutTask("CarlaNav-v0", {**FAST, "max_steps": 15}, spec, params[i:i + 1],
                                       np.array([4 + i]), seeds[i:i + 1, e:e + 1]))
            assert one.returns[0, 0] == out.returns[i, e]
    tr = out.transitions[1]
    assert tr.member == 5 and tr.generation == 2 and len(tr) == 30
    np.testing.assert_array_equal(tr.episode, [0] * 15 + [1] * 15)
    np.testing.assert_array_equal(tr.step, list(range(15)) * 2)
    assert tr.episode_returns() == pytest.approx(out.returns[1], rel=1e-6)


def test_rollout_marks_a_lost_server_as_a_worker_fault(server):
    spec = MLPSpec(38, 2, (4,))
    task = RolloutTask("CarlaNav-v0", {**FAST, "port": 2300}, spec, np.zeros((1, spec.num_params), np.float32),
                       np.array([0]), np.array([[0]]))
    with pytest.raises(EnvError, match="no CARLA server answers at localhost:2300") as err:
        run_task(task)
    assert err.value.worker_fault
    import pickle

    assert pickle.loads(pickle.dumps(err.value)).worker_fault  # crosses to the trainer's process


@pytest.mark.parametrize("method", ["vanilla", "shaped", "ppo"])
def test_train_two_generations_with_every_kind_of_method(server, tmp_path, method):
    from helpers import train

    cfg = {"env": "CarlaNav-v0", "env_kwargs": {**FAST, "route_length": [20.0, 400.0], "max_steps": 12},
           "method": method, "executor": "inline", "generations": 2, "seed": 1, "es": {"pairs": 2},
           "policy": {"hidden": [4]}, "rollout": {"episodes": 2, "test_episodes": 2}, "tensorboard": False}
    rows = train(tmp_path / method, cfg).read_metrics()
    assert len(rows) == 2 and all(np.isfinite(float(r["test_reward_mean"])) for r in rows)
    connection.close_all()  # what runs at exit: envs the rollout layer cached are never closed
    assert server.actors == {} and not server.settings.synchronous_mode
