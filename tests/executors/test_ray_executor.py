"""The Ray executor on a real two-node local Ray cluster (loopback only): results, faults, training.

One cluster (two nodes on this machine, one CPU each) and one driver connection serve the whole module
(Ray starts worker processes per connection); tests build executors with their own fault settings.
"""

import pytest

ray = pytest.importorskip("ray", reason="ray is not installed (pip install 'shaped-es[ray]')")

from executor_faults import (  # noqa: E402
    FailAlways,
    FailOnce,
    FaultyExecutor,
    SquareOnNode,
    raise_on_three,
    square,
)
from helpers import CARTPOLE_TINY, strip_time, train  # noqa: E402
from loopback_check import listening_addresses, non_loopback  # noqa: E402
from ray.cluster_utils import Cluster  # noqa: E402

from shaped_es.executors import ExecutorError, make_executor  # noqa: E402
from shaped_es.executors.ray_executor import LOOPBACK, RayExecutor  # noqa: E402

TASKS = list(range(6))
EXPECTED = [x * x for x in TASKS]
TINY = {**CARTPOLE_TINY, "generations": 4}


@pytest.fixture(scope="module")
def cluster(ray_env):
    node = {"node_ip_address": LOOPBACK, "num_cpus": 1, "object_store_memory": 100 * 2**20}
    c = Cluster(initialize_head=True, head_node_args={**node, "include_dashboard": False})
    try:
        c.add_node(**node)
        c.wait_for_nodes()
        yield c
    finally:
        if ray.is_initialized():
            ray.shutdown()
        c.shutdown()


@pytest.fixture(scope="module")
def driver(cluster):
    """One driver connection for the module (Ray starts worker processes per connection)."""
    owner = RayExecutor(address=cluster.address)
    yield owner
    owner.shutdown()
    assert not ray.is_initialized(), "the executor that connected must disconnect on shutdown"


@pytest.fixture
def connect(cluster, driver):
    """Executors with their own fault settings over the module's connection (they do not own it)."""

    def _make(**opts) -> RayExecutor:
        return RayExecutor(address=cluster.address, **{"max_retries": 2, **opts})

    yield _make
    assert ray.is_initialized(), "an executor that did not connect must not disconnect"


def test_two_loopback_nodes_and_nothing_listens_elsewhere(connect):
    ex = connect()
    nodes = [n for n in ray.nodes() if n["Alive"]]
    assert len(nodes) == 2 and ex.workers == 2
    assert {n["NodeManagerAddress"] for n in nodes} == {LOOPBACK}
    assert ray.util.get_node_ip_address() == LOOPBACK
    listening = listening_addresses()
    assert listening and not non_loopback(listening), listening


def test_map_uses_both_nodes_in_task_order(connect, tmp_path):
    ex = connect()
    out = ex.map(SquareOnNode(str(tmp_path), 2), TASKS)  # each task waits until both nodes run one
    assert [v for v, _ in out] == EXPECTED
    assert len({node for _, node in out}) == 2


def test_worker_killed_mid_map_costs_one_retry(connect, tmp_path):
    ex = connect()
    marker = tmp_path / "died"
    assert ex.map(FailOnce(square, str(marker), "exit", only_value=3), TASKS) == EXPECTED
    assert marker.exists() and ex.retries == 1


def test_worker_fault_raised_by_the_task_is_retried(connect, tmp_path):
    """A task whose env lost its simulator server (an exception with ``worker_fault``) runs again."""
    ex = connect()
    marker = tmp_path / "lost"
    assert ex.map(FailOnce(square, str(marker), "fault", only_value=3), TASKS) == EXPECTED
    assert marker.exists() and ex.retries == 1
    futures = [ex.submit(FailOnce(square, str(tmp_path / "lost2"), "fault", only_value=4), t) for t in TASKS]
    assert ex.collect(square, TASKS, futures) == EXPECTED  # the faulted attempt ran again (else it raises)


def test_hung_task_is_cancelled_and_retried(connect, tmp_path):
    # The timeout counts from submission, so on a loaded machine the tasks queued behind the hung one on
    # the other node's one CPU may time out too and be retried like it (4 retries were seen): the verdict
    # is that the hung attempt was cut off and its task retried (its 4 is in the results; it never
    # returns), with retries to spare, whatever the machine's speed.
    ex = connect(task_timeout_s=2.0, max_retries=10)
    marker = tmp_path / "hung"
    assert ex.map(FailOnce(square, str(marker), "hang", only_value=2), TASKS) == EXPECTED
    assert marker.exists() and ex.retries >= 1


def test_retries_run_out_with_one_line_error(connect):
    ex = connect(max_retries=1)
    with pytest.raises(ExecutorError) as err:
        ex.map(FailAlways("exit"), [1])
    msg = str(err.value)
    assert "\n" not in msg and "failed 2 time(s)" in msg and "WorkerCrashedError" in msg


def test_task_exception_propagates_and_already_initialized_is_refused(connect):
    ex = connect()
    with pytest.raises(ValueError, match="task three is broken"):
        ex.map(raise_on_three, TASKS)
    assert ex.map(square, TASKS) == EXPECTED
    with pytest.raises(ExecutorError, match="already initialized"):
        RayExecutor()  # laptop mode never silently reuses a connected cluster


def _train(tmp_path, name, runner=None, **over):
    return strip_time(train(tmp_path / name, {**TINY, **over}, executor=runner).read_metrics())


def test_training_on_ray_equals_process_even_when_a_worker_dies(cluster, driver, tmp_path):
    reference = _train(tmp_path, "process", executor="process", workers=2)
    on_ray = _train(tmp_path, "ray", executor="ray", address=cluster.address)  # built from the config
    assert on_ray == reference
    inner = make_executor("ray", workers=2, address=cluster.address, max_retries=2, task_timeout_s=None)
    faulty = FaultyExecutor(inner, str(tmp_path / "died"), generation=2)
    try:
        killed = _train(tmp_path, "ray-killed", runner=faulty)
        assert inner.retries == 1 and (tmp_path / "died").exists()
    finally:
        faulty.shutdown()
    assert killed == reference
