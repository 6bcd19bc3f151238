"""CarlaNav-v0 on a LIVE CARLA server: runs only when ``SHAPED_ES_CARLA=host:port`` is set and a server
answers there (with the ``carla`` extra installed); skipped otherwise, with the reason.

    SHAPED_ES_CARLA=localhost:2000 python -m pytest tests/envs/test_carla_live.py -q
"""

import math
import os

import numpy as np
import pytest

ADDRESS = os.environ.get("SHAPED_ES_CARLA", "")


def _server() -> tuple[str, int]:
    if not ADDRESS:
        pytest.skip("no live CARLA server: set SHAPED_ES_CARLA=host:port to run these tests")
    carla = pytest.importorskip("carla", reason="the carla client is not installed: pip install -e '.[carla]'")
    host, _, port = ADDRESS.rpartition(":")
    try:
        client = carla.Client(host, int(port))
        client.set_timeout(5.0)
        client.get_server_version()
    except (RuntimeError, ValueError) as exc:
        pytest.skip(f"SHAPED_ES_CARLA={ADDRESS}: no CARLA server answers ({str(exc).splitlines()[0]})")
    return host, int(port)


@pytest.fixture(scope="module")
def address():
    return _server()


def test_a_few_steps_on_the_server(address):
    import gymnasium as gym

    import shaped_es  # noqa: F401 - registers the envs

    host, port = address
    env = gym.make("CarlaNav-v0", host=host, port=port, worker_index=0)
    try:
        obs, info = env.reset(seed=0)
        assert obs.shape == (38,) and np.all(np.abs(obs) <= 1.0)
        for t in range(30):
            obs, r, term, trunc, info = env.step(np.array([0.5, 0.6], np.float32))  # gentle left turn
            assert obs.shape == (38,) and math.isfinite(r)
            assert set(info) >= {"position", "waypoint", "reward_waypoint", "reward_step", "reward_collision"}
            if term or trunc:
                break
        # the frame conversion: a left turn is a positive yaw rate (obs[5]) and forward speed is positive
        assert obs[3] > 0.0 and obs[5] > 0.0, obs[:6]
    finally:
        env.close()


def test_train_two_generations(address, tmp_path):
    from shaped_es.cli.commands import main

    host, port = address
    code = main(["train", "--env", "CarlaNav-v0", "--method", "shaped", "--executor", "inline",
                 "--generations", "2", "--pairs", "2", "--set", "rollout.episodes=1",
                 "--set", "rollout.test_episodes=1", "--set", "policy.hidden=[8]", "--set", "tensorboard=false",
                 "--set", f"env_kwargs.host={host}", "--set", f"env_kwargs.port={port}",
                 "--set", "env_kwargs.max_steps=50", "--quiet", "--out", str(tmp_path / "run")])
    assert code == 0
