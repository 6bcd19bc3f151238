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


@pytest.mark.parametrize("method", list(RUNS))
def test_same_rows_inline_and_with_1_or_2_worker_processes(tmp_path, method):
    cfg = write_config(tmp_path / "c.yaml", RUNS[method])
    rows = {}
    for name, flags in WHERE.items():
        res = run_cli("train", "--config", cfg, *flags, "--out", tmp_path / name, "--quiet")
        assert res.returncode == 0, res.stderr
        rows[name] = strip_time(RunStore(tmp_path / name).read_metrics())
    assert rows["process-1"] == rows["inline"]
    assert rows["process-2"] == rows["inline"]


def test_an_inline_run_resumed_with_2_processes_continues_exactly(tmp_path):
    cfg = write_config(tmp_path / "c.yaml", RUNS["vanilla"])
    assert run_cli("train", "--config", cfg, "--executor", "inline", "--out", tmp_path / "ref", "--quiet"
                   ).returncode == 0
    assert run_cli("train", "--config", cfg, "--executor", "inline", "--generations", 2, "--out", tmp_path / "r",
                   "--quiet").returncode == 0
    res = run_cli("resume", tmp_path / "r", "--generations", 3, "--executor", "process", "--workers", 2, "--quiet")
    assert res.returncode == 0, res.stderr
    assert strip_time(RunStore(tmp_path / "r").read_metrics()) == strip_time(RunStore(tmp_path / "ref").read_metrics())
