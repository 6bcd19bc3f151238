"""A run's numbers do not depend on where its rollouts ran: one seed trained inline, with the process
executor on 1 worker and on 2 workers gives the same metrics rows, times aside (before: the test rewards
differed in the last digits, -1041.0843555 vs -1041.0843358, because the test episodes were split over
the workers and one BLAS product over a chunk rounds by the chunk's size; they now run rowwise, as
``evaluate``'s). For an ES method and the shaped one; and an inline run resumed with 2 processes
continues exactly."""

from __future__ import annotations

import pytest
from fault_run import config, run_cli, write_config
from helpers import strip_time

from shaped_es.rundir.store import RunStore

RUNS = {"vanilla": dict(env="Pendulum-v1", method="vanilla", generations=3, es={"pairs": 4},
                        rollout={"episodes": 1, "test_episodes": 5}, policy={"hidden": [8]}, tensorboard=False),
        "shaped": config("shaped", generations=3, rollout={"episodes": 1, "test_episodes": 5})}
WHERE = {"inline": ["--executor", "inline"], "process-1": ["--executor", "process", "--workers", "1"],
         "process-2": ["--executor", "process", "--workers", "2"]}


def _train(tmp, method: str, where: str) -> list[dict]:
    """The rows (times aside) of ``RUNS[method]`` trained by the command line with ``WHERE[where]``."""
    cfg = write_config(tmp / "c.yaml", RUNS[method])
    res = run_cli("train", "--config", cfg, *WHERE[where], "--out", tmp / where, "--quiet")
    assert res.returncode == 0, res.stderr
    return strip_time(RunStore(tmp / where).read_metrics())


@pytest.fixture(scope="module")
def inline_rows(tmp_path_factory):
    """``inline_rows(method)``: the inline run of each method, trained once for the module (both tests
    below compare against the same uninterrupted inline run of RUNS['vanilla'])."""
    done: dict[str, list[dict]] = {}

    def rows(method: str) -> list[dict]:
        if method not in done:
            done[method] = _train(tmp_path_factory.mktemp(f"inline-{method}"), method, "inline")
        return done[method]

    return rows


@pytest.mark.parametrize("method", list(RUNS))
def test_same_rows_inline_and_with_1_or_2_worker_processes(tmp_path, method, inline_rows):
    assert _train(tmp_path, method, "process-1") == inline_rows(method)
    assert _train(tmp_path, method, "process-2") == inline_rows(method)


def test_an_inline_run_resumed_with_2_processes_continues_exactly(tmp_path, inline_rows):
    cfg = write_config(tmp_path / "c.yaml", RUNS["vanilla"])
    assert run_cli("train", "--config", cfg, "--executor", "inline", "--generations", 2, "--out", tmp_path / "r",
                   "--quiet").returncode == 0
    res = run_cli("resume", tmp_path / "r", "--generations", 3, "--executor", "process", "--workers", 2, "--quiet")
    assert res.returncode == 0, res.stderr
    assert strip_time(RunStore(tmp_path / "r").read_metrics()) == inline_rows("vanilla")
