"""Laptop mode: ``RayExecutor()`` without an address starts a private, loopback-only local Ray.

(Its own module: Ray cannot connect to a multi-node cluster after a local instance ran in the same
process -- tasks on the other node then fail with OwnerDiedError, a Ray limitation.)
"""

import os

import pytest

ray = pytest.importorskip("ray", reason="ray is not installed (pip install 'shaped-es[ray]')")

from executor_faults import FailOnce, square  # noqa: E402
from loopback_check import listening_addresses, non_loopback  # noqa: E402

from shaped_es.executors import make_executor  # noqa: E402
from shaped_es.executors.ray_executor import LOOPBACK  # noqa: E402

TASKS = list(range(6))


def test_private_loopback_ray_that_ignores_ray_address(ray_env, tmp_path, monkeypatch):
    monkeypatch.setenv("RAY_ADDRESS", "127.0.0.1:9")  # a cluster address that must not be used
    ex = make_executor("ray", workers=1, max_retries=1, task_timeout_s=None)
    try:
        assert len(ray.nodes()) == 1 and ray.cluster_resources()["CPU"] == 1 and ex.workers == 1
        assert ray.util.get_node_ip_address() == LOOPBACK
        listening = listening_addresses()
        assert listening and not non_loopback(listening), listening
        marker = tmp_path / "died"
        assert ex.map(FailOnce(square, str(marker), "exit", only_value=4), TASKS) == [x * x for x in TASKS]
        assert ex.retries == 1 and marker.exists()
    finally:
        ex.shutdown()
    assert not ray.is_initialized()
    assert os.environ["RAY_ADDRESS"] == "127.0.0.1:9"
