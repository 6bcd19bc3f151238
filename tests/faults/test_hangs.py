"""Test episodes get the training rollouts' fault handling (timeouts, pool rebuilds), every hang is
bounded, the inline executor says it cannot time out, and workers die with a killed trainer."""

from __future__ import annotations

import os
import signal
import time

import numpy as np
import pytest
from fault_run import config, popen_cli, write_config
from helpers import strip_time, train

from shaped_es import seeding
from shaped_es.cli.commands import main

FAULTY = "fault_envs:Faulty-v0"


def _test_seeds(cfg: dict, g: int) -> list[int]:
    E = cfg["rollout"]["test_episodes"]
    return seeding.episode_seeds(cfg["seed"], seeding.TEST, g, np.zeros(1), E)[0].tolist()


def _train(root, cfg: dict) -> list[dict]:
    return train(root, cfg).read_metrics()


def _cfg(**over) -> dict:
    return config("vanilla", **{"env": FAULTY, "generations": 4, "executor": "process", "workers": 2, **over})


@pytest.mark.timeout(240)
@pytest.mark.parametrize("fault, extra", [
    ("hang", {"task_timeout_s": 4.0}),  # hangs forever in a test episode: cut off after 4 s, rerun
    ("exit", {"eval_workers": 2}),  # the separate evaluation pool loses a worker: rebuilt, rerun
    ("exit", {}),  # the shared pool loses a worker during a test episode
], ids=["hang-timeout", "dead-eval-worker", "dead-shared-worker"])
def test_test_episodes_survive_hangs_and_dead_workers(tmp_path, faults_path, fault, extra):
    cfg = _cfg(**extra)
    ref = _train(tmp_path / "ref", cfg)
    marker = tmp_path / "marker"
    kwargs = {"fault": fault, "seeds": _test_seeds(cfg, 1), "marker": str(marker)}
    t0 = time.perf_counter()
    rows = _train(tmp_path / "faulty", {**cfg, "env_kwargs": kwargs})
    assert marker.exists(), "the fault must have fired"
    assert strip_time(rows) == strip_time(ref)
    assert time.perf_counter() - t0 < 200


@pytest.mark.timeout(240)
def test_hung_training_episode_is_cut_off(tmp_path, faults_path):
    cfg = _cfg(task_timeout_s=4.0)
    ref = _train(tmp_path / "ref", cfg)
    seeds = seeding.episode_seeds(cfg["seed"], seeding.TRAIN, 2, np.zeros(1), 1)[0].tolist()
    marker = tmp_path / "marker"
    rows = _train(tmp_path / "faulty", {**cfg, "env_kwargs": {"fault": "hang", "seeds": seeds,
                                                              "marker": str(marker)}})
    assert marker.exists() and strip_time(rows) == strip_time(ref)


def test_inline_executor_says_task_timeout_cannot_apply(tmp_path, capsys):
    cfg = write_config(tmp_path / "c.yaml", config("vanilla", generations=1, task_timeout_s=5.0))
    assert main(["train", "--config", str(cfg), "--out", str(tmp_path / "r"), "--quiet"]) == 0
    err = [l for l in capsys.readouterr().err.splitlines() if l.strip()]
    assert len(err) == 1 and err[0].startswith("shaped-es: warning: task_timeout_s=5 cannot apply to the "
                                               "inline executor"), err


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:  # a zombie (dead, not yet reaped by its parent) is not alive
        return open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.timeout(180)
@pytest.mark.parametrize("executor", ["process", pytest.param("ray", marks=pytest.mark.slow)])
def test_workers_stuck_in_env_step_die_with_a_killed_trainer(tmp_path, faults_path, executor):
    if executor == "ray":
        pytest.importorskip("ray")
    marker = tmp_path / "stuck"
    cfg = _cfg(executor=executor, env_kwargs={"fault": "hang", "marker": str(marker)})
    p = popen_cli("train", "--config", write_config(tmp_path / "c.yaml", cfg), "--out", tmp_path / "r",
                  "--quiet")
    deadline = time.time() + 120
    while not (marker.exists() and marker.read_text()):
        assert time.time() < deadline and p.poll() is None, p.communicate()
        time.sleep(0.05)
    worker = int(marker.read_text())
    assert worker != p.pid and _alive(worker)
    p.send_signal(signal.SIGKILL)
    p.wait()
    deadline = time.time() + 30
    while _alive(worker) and time.time() < deadline:
        time.sleep(0.1)
    assert not _alive(worker), f"worker {worker} outlived the killed trainer"
