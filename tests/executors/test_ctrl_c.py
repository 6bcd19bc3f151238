"""Ctrl-C during a run with worker processes (issue 29): the terminal sends SIGINT to the whole process
group; the workers ignore it and the trainer alone answers, with its one line and the resume command, no
worker ``KeyboardInterrupt`` traceback. The run then resumes."""

import os
import signal
import subprocess
import sys
import time

from helpers import SRC
from shaped_es.executors.process import ProcessExecutor


def _sigint_disposition(_):
    return signal.getsignal(signal.SIGINT) is signal.SIG_IGN


def test_workers_ignore_sigint():
    before = signal.getsignal(signal.SIGINT)  # Python's default_int_handler, or SIG_IGN under `nohup ... &`
    with ProcessExecutor(workers=2) as ex:
        assert ex.map(_sigint_disposition, [0, 1, 2, 3]) == [True] * 4
    assert signal.getsignal(signal.SIGINT) is before  # the parent keeps its own


def _rows(run) -> int:
    m = run / "metrics.csv"
    return len(m.read_text().splitlines()) - 1 if m.is_file() else 0


def test_ctrl_c_prints_only_the_resume_line(tmp_path):
    run = tmp_path / "r"
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    args = ["--env", "CartPole-v1", "--method", "vanilla", "--executor", "process", "--workers", "2",
            "--pairs", "4", "--set", "tensorboard=false", "--quiet"]
    p = subprocess.Popen([sys.executable, "-m", "shaped_es.cli.commands", "train", *args, "--generations", "1000",
                          "--out", str(run)], env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         text=True, start_new_session=True)  # its own process group, as a terminal's job
    deadline = time.monotonic() + 240
    while _rows(run) < 2 and p.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(p.pid, signal.SIGINT)  # what Ctrl-C does: every process of the group, workers included
    out, err = p.communicate(timeout=240)
    assert p.returncode == 130, err
    assert err.splitlines() == [f"shaped-es: interrupted; continue with: shaped-es resume {run}"]
    more = _rows(run) + 2  # the resume continues from the last checkpoint (rows past it are redone)
    res = subprocess.run([sys.executable, "-m", "shaped_es.cli.commands", "resume", str(run), "--generations",
                          str(more), "--quiet"], env=env, capture_output=True, text=True, timeout=240)
    assert res.returncode == 0, res.stderr
    assert _rows(run) == more
