"""One writer per run directory: a second train/resume/benchmark is refused in one line while the first
runs, a lock of a dead process is taken over, and nothing the first wrote is duplicated."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest
from fault_run import config, env, one_error_line, popen_cli, run_cli, snapshot, write_config

from shaped_es.cli.commands import main
from shaped_es.rundir.store import RunStore, StoreError

HOLD = """
import sys, time
from shaped_es.rundir.store import RunStore
with RunStore(sys.argv[1]).lock():
    print("locked", flush=True)
    time.sleep(float(sys.argv[2]))
"""


def _holder(run, seconds=60.0) -> subprocess.Popen:
    p = subprocess.Popen([sys.executable, "-c", HOLD, str(run), str(seconds)], env=env(),
                         stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "locked"
    return p


def test_resume_while_training_is_refused_and_rows_are_not_duplicated(tmp_path, faults_path):
    # the case: cmaes, 8 generations inline; resume as soon as latest.json exists (the env sleeps
    # 5 ms a step, so that the training outlasts the second command's start-up)
    cfg = write_config(tmp_path / "c.yaml", config("cmaes", generations=8, env="fault_envs:Faulty-v0",
                                                   env_kwargs={"fault": "slow"}))
    run = tmp_path / "r"
    train = popen_cli("train", "--config", cfg, "--out", run, "--quiet")
    deadline = time.time() + 120
    while not (run / "checkpoints" / "latest.json").exists():
        assert time.time() < deadline and train.poll() is None, train.communicate()
        time.sleep(0.01)
    second = run_cli("resume", run, "--quiet")
    out, err = train.communicate(timeout=300)
    assert train.returncode == 0, err
    assert second.returncode == 2
    line = one_error_line(second.stderr)
    assert "is in use by process" in line and str(train.pid) in line
    gens = [int(r["generation"]) for r in RunStore(run).read_metrics()]
    assert gens == list(range(8))
    assert not (run / ".lock").exists()


@pytest.mark.parametrize("command", ["train", "resume", "benchmark"])
def test_a_live_lock_refuses_train_resume_and_benchmark(tmp_path, capsys, command):
    run = tmp_path / "r"
    assert main(["train", "--config", str(write_config(tmp_path / "c.yaml", config("vanilla",
                                                                                   generations=1))),
                 "--out", str(run), "--quiet"]) == 0
    before = (run / "metrics.csv").read_bytes()
    capsys.readouterr()
    target = run
    if command == "benchmark":  # the benchmark's run directory of (vanilla, seed 0)
        bench = tmp_path / "b"
        args = ["benchmark", "--env", "CartPole-v1", "--methods", "vanilla", "--seeds", "1",
                "--generations", "1", "--executor", "inline", "--set", "es.pairs=2", "--set",
                "rollout.test_episodes=1", "--set", "tensorboard=false", "--quiet", "--out", str(bench)]
        target = bench / "runs" / "vanilla_s0"
        target.mkdir(parents=True)
    holder = _holder(target)
    try:
        if command == "train":
            args = ["train", "--env", "CartPole-v1", "--out", str(run), "--quiet"]
        elif command == "resume":
            args = ["resume", str(run), "--generations", "2", "--quiet"]
        assert main(args) == 2
        err = capsys.readouterr().err
        line = one_error_line(err)
        assert ("is in use by process" in line and str(holder.pid) in line) or "holds a run" in line
    finally:
        holder.kill()
        holder.wait()
    assert (run / "metrics.csv").read_bytes() == before


def test_lock_of_a_killed_process_is_taken_over(tmp_path, capsys):
    run = tmp_path / "r"
    cfg = write_config(tmp_path / "c.yaml", config("vanilla", generations=2))
    assert main(["train", "--config", str(cfg), "--out", str(run), "--quiet"]) == 0
    holder = _holder(run)
    holder.kill()  # SIGKILL: its .lock file stays behind, with its pid
    holder.wait()
    assert (run / ".lock").exists()
    assert main(["resume", str(run), "--generations", "3", "--quiet"]) == 0
    assert not (run / ".lock").exists()
    assert [int(r["generation"]) for r in RunStore(run).read_metrics()] == [0, 1, 2]


def test_lock_is_reentrant_in_one_process_and_released(tmp_path):
    store = RunStore(tmp_path / "r")
    with store.lock():
        with store.lock():
            assert store.holds_lock() and store.lock_path.exists()
        assert store.holds_lock()
    assert not store.holds_lock() and not store.lock_path.exists()
    p = _holder(store.root, 30)
    try:
        with pytest.raises(StoreError, match="is in use by process"):
            with store.lock():
                pass
        with pytest.raises(StoreError, match="is in use"):  # a write outside the lock is refused too
            store.append_metrics({"generation": 0})
    finally:
        p.kill()
        p.wait()
    store.append_metrics({"generation": 0})
    assert os.path.getsize(store.metrics_path) > 0


def test_a_lock_that_is_a_symlink_is_refused_and_its_target_untouched(tmp_path):
    """An auditor's ``ln -s /x/precious RUN/.lock``: the lock used to open the target, empty it and write the
    owner record there; now the run is refused in one line and the target keeps its bytes."""
    store = RunStore(tmp_path / "r")
    store.root.mkdir()
    precious = tmp_path / "precious"
    precious.write_text("mine")
    store.lock_path.symlink_to(precious)
    with pytest.raises(StoreError, match=r"\.lock is a symlink; a run's lock is a file of its own"):
        with store.lock():
            pass
    assert precious.read_text() == "mine" and store.lock_path.is_symlink()


def test_a_deleted_lock_file_lets_no_second_writer_in(tmp_path, capsys):
    run = tmp_path / "r"
    cfg = write_config(tmp_path / "c.yaml", config("vanilla", generations=1))
    assert main(["train", "--config", str(cfg), "--out", str(run), "--quiet"]) == 0
    before = snapshot(run)
    holder = _holder(run)
    try:
        (run / ".lock").unlink()  # a stray rm while the holder runs
        capsys.readouterr()
        assert main(["resume", str(run), "--generations", "2", "--quiet"]) == 2
        line = one_error_line(capsys.readouterr().err)
        assert "is in use by another process (its .lock file, which names it, was removed" in line
        with pytest.raises(StoreError, match="is in use"):  # a write outside the lock is refused too
            RunStore(run).append_metrics({"generation": 1})
    finally:
        holder.kill()
        holder.wait()
    assert snapshot(run) == before
    assert main(["resume", str(run), "--generations", "2", "--quiet"]) == 0  # the holder's lock died with it
