"""Ctrl-C during a run with worker processes (issue 29): the terminal sends SIGINT to the whole process
group; the workers ignore it and the trainer alone answers, with its one line and the resume command, no
worker ``KeyboardInterrupt`` traceback. The run then resumes."""

import os
import signal
import subprocess
import sys
import time

import pytest

from helpers import SRC
from shaped_es.executors.process import ProcessExecutor


def _sigint_disposition(_):
    blocked = signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, [])  # born blocked, unblocked at start
    return signal.getsignal(signal.SIGINT) is signal.SIG_IGN and not blocked


def test_workers_ignore_sigint():
    before = signal.getsignal(signal.SIGINT)  # Python's default_int_handler, or SIG_IGN under `nohup ... &`
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, [])
    with ProcessExecutor(workers=2) as ex:
        assert ex.map(_sigint_disposition, [0, 1, 2, 3]) == [True] * 4
    assert signal.getsignal(signal.SIGINT) is before  # the parent keeps its own
    assert signal.pthread_sigmask(signal.SIG_BLOCK, []) == mask  # and its signal mask


def _default_sigint() -> None:
    """preexec_fn: the child starts with SIGINT at its default and unblocked, as a terminal's job does,
    whatever this pytest process inherited (a shell's background job is started with SIGINT ignored, and
    an ignored SIGINT survives exec: Python would then never raise KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, [signal.SIGINT])


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
                         text=True, start_new_session=True,  # its own process group, as a terminal's job
                         preexec_fn=_default_sigint)
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


# sitecustomize.py for the processes multiprocessing starts (the forkserver, a spawned worker, the resource
# tracker: their command lines name it): each sends itself SIGINT while its interpreter starts, as a Ctrl-C
# in that moment would
_SIGINT_AT_START = """import os, signal, sys
if "multiprocessing" in " ".join(getattr(sys, "orig_argv", None) or sys.argv or []):
    os.kill(os.getpid(), signal.SIGINT)
"""


@pytest.mark.parametrize("start_method", ["forkserver", "spawn"])
def test_ctrl_c_while_the_workers_start_prints_nothing_from_them(tmp_path, start_method):
    """A Ctrl-C while the pool starts reaches the forkserver and the workers before they ignore SIGINT: they
    are born with it blocked (then ignore it), so none ends with a KeyboardInterrupt traceback (or a
    "Fatal Python error: init_import_site"); the pool starts and works."""
    (tmp_path / "sitecustomize.py").write_text(_SIGINT_AT_START)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(SRC)])}
    code = ("from shaped_es.executors.process import ProcessExecutor\n"
            f"with ProcessExecutor(workers=2, start_method={start_method!r}) as ex:\n"
            "    print(ex.map(abs, [-1, -2, -3]))\n")
    res = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True,
                         timeout=120, preexec_fn=_default_sigint)
    assert (res.returncode, res.stdout, res.stderr) == (0, "[1, 2, 3]\n", "")


# sitecustomize.py for the forkserver: it sends SIGINT to the trainer (its parent) as it starts, i.e. while
# the trainer waits for the forkserver to fork the first worker
_SIGINT_TO_PARENT = """import os, signal, sys
if "multiprocessing.forkserver" in " ".join(getattr(sys, "orig_argv", None) or sys.argv or []):
    os.kill(os.getppid(), signal.SIGINT)
"""


def test_ctrl_c_while_the_workers_start_waits_until_the_pool_knows_them(tmp_path):
    """A Ctrl-C that reaches the trainer while it starts the workers takes effect once every worker is
    started and known to the pool (so shutdown ends them); one started after the trainer's clean-up had
    begun would fail on its pool's semaphores, gone by then, with a traceback."""
    (tmp_path / "sitecustomize.py").write_text(_SIGINT_TO_PARENT)
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path), str(SRC)])}
    code = ("from shaped_es.executors.process import ProcessExecutor\n"
            "ex = ProcessExecutor(workers=2, start_method='forkserver')\n"
            "try:\n"
            "    ex.map(abs, [-1])\n"
            "except KeyboardInterrupt:\n"
            "    print('interrupted;', len(ex._pool._processes), 'workers started')\n"
            "finally:\n"
            "    ex.shutdown()\n")
    res = subprocess.run([sys.executable, "-c", code], env=env, cwd=tmp_path, capture_output=True, text=True,
                         timeout=120, preexec_fn=_default_sigint)
    assert (res.returncode, res.stdout, res.stderr) == (0, "interrupted; 2 workers started\n", "")
