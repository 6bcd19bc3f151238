"""Signals end a run in one line with the resume hint (a real process, its own session): SIGTERM with
the process executor ends as Ctrl-C does (before: killed by the signal, no hint, Python's "leaked
semaphore objects" warning); a double Ctrl-C prints one line, not a traceback per interrupted clean-up
step."""

from __future__ import annotations

import os
import signal
import time

import pytest
from fault_run import popen_cli

SLOW = ["train", "--env", "fault_envs:Faulty-v0", "--set", "env_kwargs.fault=slow", "--executor", "process",
        "--workers", "2", "--generations", "200", "--pairs", "4", "--set", "tensorboard=false", "--quiet"]


def _started(run, proc, timeout=120):
    deadline = time.time() + timeout
    while not (run / "metrics.csv").is_file():  # a generation ran: workers are busy with the next
        assert proc.poll() is None and time.time() < deadline
        time.sleep(0.2)


@pytest.mark.parametrize("how, code, word", [("sigterm", 143, "terminated (SIGTERM)"),
                                             ("ctrl-c-twice", 130, "interrupted")])
def test_a_signal_is_one_line_with_the_resume_hint(tmp_path, faults_path, how, code, word):
    run = tmp_path / "run"
    proc = popen_cli(*SLOW, "--out", run, start_new_session=True)
    try:
        _started(run, proc)
        if how == "sigterm":
            proc.send_signal(signal.SIGTERM)
        else:  # Ctrl-C reaches the terminal's whole process group, workers included
            os.killpg(proc.pid, signal.SIGINT)
            time.sleep(0.3)
            os.killpg(proc.pid, signal.SIGINT)
        out, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == code, err
    assert err.strip().splitlines() == [f"shaped-es: {word}; continue with: shaped-es resume {run}"], err
    assert not (run / ".lock").exists()
