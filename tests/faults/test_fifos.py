"""A run reads and writes regular files only: ``metrics.csv``, ``checkpoints/latest.json``, ``error.log``,
``config.yaml`` (or a checkpoint) replaced by a named pipe is refused in one line at once (before: resume
waited forever), and ``config.yaml`` that is a folder is named as one; a config *given* as a pipe
(``--config /dev/stdin``) is read. Each a real process with a timeout."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest
import yaml
from fault_run import HERE, env, newest, one_error_line, run_cli, snapshot

TINY = ["--env", "Pendulum-v1", "--method", "vanilla", "--generations", "2", "--pairs", "2", "--executor",
        "inline", "--set", "rollout.test_episodes=1", "--set", "tensorboard=false", "--set",
        "policy.hidden=[4]", "--quiet"]


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    run = tmp_path_factory.mktemp("fifo") / "run"
    res = run_cli("train", *TINY, "--out", run)
    assert res.returncode == 0, res.stderr
    (run / "error.log").write_text("")
    return run


def fifo(rel):
    def f(run):
        p = newest(run, rel) if rel.startswith(".") else run / rel
        p.unlink()
        os.mkfifo(p)
        return p.name
    return f


CASES = [("metrics.csv", fifo("metrics.csv")), ("latest.json", fifo("checkpoints/latest.json")),
         ("error.log", fifo("error.log")), ("config.yaml", fifo("config.yaml")), ("checkpoint-npz", fifo(".npz"))]


@pytest.mark.parametrize("command", ["resume", "evaluate"])
@pytest.mark.parametrize("damage", [c[1] for c in CASES], ids=[c[0] for c in CASES])
def test_a_named_pipe_is_refused_at_once(base, tmp_path, damage, command):
    run = tmp_path / "run"
    shutil.copytree(base, run)
    name = damage(run)
    before = snapshot_files(run)
    argv = ["resume", run, "--generations", 3, "--quiet"] if command == "resume" else ["evaluate", run,
                                                                                         "--episodes", 1]
    res = run_cli(*argv, timeout=60)  # before: never returned
    if command == "evaluate" and name in ("metrics.csv", "error.log"):  # evaluate reads neither
        assert res.returncode == 0, res.stderr
        return
    assert res.returncode == 2, res.stderr
    line = one_error_line(res.stderr)
    assert f"{name} is a named pipe, not a regular file" in line, line
    assert snapshot_files(run) == before


def snapshot_files(run):
    """sha256 of the regular files (the pipe itself cannot be hashed), and the pipe's name."""
    pipes = sorted(str(p.relative_to(run)) for p in run.rglob("*") if p.is_fifo())
    hidden = run.parent / "hidden"
    hidden.mkdir(exist_ok=True)
    for rel in pipes:  # snapshot() reads files: move the pipes aside meanwhile
        os.rename(run / rel, hidden / rel.replace("/", "_"))
    try:
        return snapshot(run), pipes
    finally:
        for rel in pipes:
            os.rename(hidden / rel.replace("/", "_"), run / rel)


def test_config_yaml_that_is_a_folder_is_named(base, tmp_path):
    run = tmp_path / "run"
    shutil.copytree(base, run)
    (run / "config.yaml").unlink()
    (run / "config.yaml").mkdir()
    res = run_cli("resume", run, "--quiet")
    assert res.returncode == 2
    assert "config.yaml is a folder, not a regular file" in one_error_line(res.stderr)


def test_config_from_stdin_is_read(tmp_path):
    cfg = {"env": "Pendulum-v1", "generations": 1, "es": {"pairs": 2}, "executor": "inline",
           "tensorboard": False, "policy": {"hidden": [4]}, "rollout": {"test_episodes": 1}}
    res = subprocess.run([sys.executable, "-m", "shaped_es.cli.commands", "train", "--config", "/dev/stdin", "--out",
                          str(tmp_path / "run"), "--quiet"], input=yaml.safe_dump(cfg), env=env(), cwd=HERE,
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    assert yaml.safe_load((tmp_path / "run" / "config.yaml").read_text())["generations"] == 1
