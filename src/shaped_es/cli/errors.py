"""How a ``shaped-es`` command ends: every error as one line and an exit code, its traceback in
``RUN/error.log``, warnings as one line, and the supervision that reports, in one line, an MPI job that
MPI itself ended (see ``main.py`` for the command line)."""

from __future__ import annotations

import argparse
import errno
import gc
import os
import signal
import subprocess
import threading
import sys
import traceback
import warnings
from pathlib import Path

from shaped_es.monitor import warning_log

USAGE_ERROR = 2
INTERNAL_ERROR = 1
_SUPERVISED = "SHAPED_ES_SUPERVISED"  # set in the child process of an MPI-supervised command


def _user_errors() -> tuple[type[BaseException], ...]:
    from shaped_es.config import ConfigError
    from shaped_es.executors import ExecutorError
    from shaped_es.rollout import EnvSpecError
    from shaped_es.rundir.store import StoreError

    from shaped_es.trainer import DivergedError

    errs: list[type[BaseException]] = [ConfigError, StoreError, EnvSpecError, ExecutorError, DivergedError]
    try:
        from shaped_es.shaping.trajectories import TrajectoryStoreError

        errs.append(TrajectoryStoreError)
    except ImportError:
        pass
    return tuple(errs)


def _run_dir(a: argparse.Namespace) -> str | None:
    """The run a command works on: ``run_dir`` (evaluate, render, resume; render's ``--out`` is its GIF), else
    ``--out`` (train, benchmark)."""
    return getattr(a, "run_dir", None) or getattr(a, "out", None)


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the command is, so that it ends as on Ctrl-C: its clean-up runs (workers
    ended, semaphores released, the lock freed) and it prints one line with the resume hint."""


def on_signals() -> dict | None:
    """Install the command's SIGINT/SIGTERM handlers (main thread only); the old ones, to restore. The
    first signal raises (``KeyboardInterrupt`` / :class:`Terminated`); later ones are ignored, so that
    a second Ctrl-C does not break the clean-up into tracebacks (the workers are killed, not awaited)."""
    if threading.current_thread() is not threading.main_thread():
        return None

    def handler(signum, frame):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        raise Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()

    return {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}


def restore_signals(old: dict | None) -> None:
    """Put the old handlers back, unless a signal came (the process is ending: a late second Ctrl-C
    must not end it by the signal, after its one line, with a traceback)."""
    if old and signal.getsignal(signal.SIGINT) is signal.SIG_IGN and old[signal.SIGINT] is not signal.SIG_IGN:
        return
    for s, h in (old or {}).items():
        signal.signal(s, h)


def continue_hint(a: argparse.Namespace) -> str:
    """How to continue the command's run, if it left one (a train that never started leaves none), or to redo an
    ``evaluate`` / ``render`` of a run."""
    run = _run_dir(a)
    if a.command == "benchmark":
        return "rerun the same command to continue (finished runs are skipped)"
    if a.command in ("evaluate", "render"):  # they change nothing in the run: the same command again
        return f"run shaped-es {a.command} again (the run is unchanged)"
    started = run and a.command in ("train", "resume") and os.path.isfile(os.path.join(run, "config.yaml"))
    return f"continue with: shaped-es resume {run}" if started else ""


def _log(a: argparse.Namespace, text: str):
    """Append ``text`` to RUN/error.log (only if the run directory exists); its path, or None."""
    from shaped_es.rundir.store import RunStore

    run = _run_dir(a)
    if not run or not text.strip():
        return None
    try:
        return RunStore(run).log_error(text)
    except Exception:  # noqa: BLE001 - logging must never hide the error itself
        return None


def _log_detail(a: argparse.Namespace, text: str) -> str:
    """Append a traceback to RUN/error.log (only if the run directory exists); returns a pointer."""
    path = _log(a, text)
    return f" (traceback in {path})" if path else ""


def error_line(exc: BaseException, a: argparse.Namespace, debug: bool) -> tuple[str, int]:
    """(the one line, exit code) for an exception that reached the command line."""
    own = getattr(exc, "detail", "")  # an env's traceback (EnvError), Ray's output (ExecutorError)
    detail = "".join(traceback.format_exception(exc))
    if own:
        detail = own + "\n" + detail
    if debug:
        print(detail, file=sys.stderr, end="")
    from shaped_es.rollout import EnvSpecError

    if isinstance(exc, _user_errors()):
        msg, code = str(exc), USAGE_ERROR
        where = _log_detail(a, detail) if own else ""
        hint = continue_hint(a) if getattr(exc, "worker_fault", False) else ""  # a lost simulator server
        from shaped_es.env_probe import EnvError

        if (own or isinstance(exc, EnvError)) and not hint and isinstance(exc, EnvSpecError) \
                and (hint := continue_hint(a)):
            # the env raised or returned a bad value (a NaN reward) mid-run: what was saved is resumable
            hint = f"once the env is fixed, {hint}"
        msg += f"; {hint}" if hint else ""
    elif isinstance(exc, MemoryError):
        msg = (f"out of memory ({_first(exc) or 'MemoryError'}); a smaller policy.hidden, es.pairs or "
               f"rollout.episodes needs less")
        code, where = USAGE_ERROR, _log_detail(a, detail)
    elif isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        hint = continue_hint(a)
        msg = (f"no space left on device{_os_where(exc)}; what was saved stays consistent (the last "
               f"checkpoint is in force){': free space, then ' + hint if hint else ''}")
        code, where = USAGE_ERROR, ""
    elif isinstance(exc, OSError):
        msg, code, where = f"{exc.strerror or _first(exc)}{_os_where(exc)}", USAGE_ERROR, _log_detail(a, detail)
    else:
        msg = f"internal error {type(exc).__name__}: {_first(exc)}"
        code, where = INTERNAL_ERROR, _log_detail(a, detail)
        where = where or " (run with --debug for the traceback)"
    msg = " ".join(msg.split())  # one line, whatever the message held
    return f"shaped-es: error: {msg}{where}", code


def _first(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else ""


def _os_where(exc: OSError) -> str:
    return f": {exc.filename}" if exc.filename else ""


class WarningRoute:
    """Where a command's warnings go (``warnings.showwarning`` while it runs): shaped-es's own (a
    category defined in ``shaped_es``: executor and env settings, repairs) as one line each; every
    other library's (Gymnasium's env checker, NumPy, Ray's output, ...) into ``RUN/error.log``
    (``monitor/warning_log.py``; the process executor's workers write theirs there too) and the terminal with
    ``--debug``, with one line at the end saying how many there were and where."""

    def __init__(self, a: argparse.Namespace, debug: bool):
        from shaped_es.rundir.store import RunStore

        run = _run_dir(a)
        self.debug, self.held = debug, []
        self.log = Path(os.path.abspath(RunStore(run).error_log)) if run else None
        self.offset = self.log.stat().st_size if self.log and self.log.is_file() else 0
        self._env = os.environ.get(warning_log.ENV)
        if self.log and not debug:  # with --debug the workers print theirs as they come
            os.environ[warning_log.ENV] = str(self.log)
        # Python shows a warning once per place ("default"), remembered per module for the whole process: a
        # warning an earlier command in this process showed (a script or notebook calling main() again) would
        # reach neither this command's error.log nor its count. Entering catch_warnings starts every module's
        # record over (the filters change, so the records are dropped); the filters themselves stay as they are.
        with warnings.catch_warnings():
            pass

    def show(self, message, category, filename, lineno, file=None, line=None) -> None:
        if category.__module__.split(".")[0] == "shaped_es":  # ExecutorWarning, EnvWarning, StoreWarning
            print(f"shaped-es: warning: {' '.join(str(message).split())}", file=sys.stderr)
            return
        text = warnings.formatwarning(message, category, filename, lineno, line)
        if self.debug:
            sys.stderr.write(text)
        source = warning_log.origin(filename)
        if not (self.log and warning_log.append(self.log, source, text)):
            self.held.append((source, text))  # no run directory yet: again at the end

    def flush(self) -> None:
        """One line for the warnings logged (or held) since the last flush."""
        held, self.held = self.held, []
        unlogged = [src for src, text in held if not (self.log and warning_log.append(self.log, src, text))]
        logged = warning_log.entries_since(self.log, self.offset) if self.log else []
        if self.log and self.log.is_file():
            self.offset = self.log.stat().st_size
        sources = logged + unlogged
        if not sources:
            return
        where = f"their text in {self.log}" if logged else ("shown above" if self.debug else "--debug shows them")
        n, names = len(sources), ", ".join(dict.fromkeys(sources))
        print(f"shaped-es: warning: {n} warning{'s' * (n > 1)} from {names} ({where})", file=sys.stderr)

    def release_interrupted(self, exc: BaseException) -> None:
        """Free what a Ctrl-C left half-built, quietly. The signal can land inside a library's constructor
        (NumPy's ``np.savez`` opening its ``ZipFile``): the half-built object's ``__del__`` then fails when
        the traceback is freed and Python prints "Exception ignored in ..." after the command's one line.
        The interrupted frames are cleared here, such errors going to ``error.log`` (the terminal with
        ``--debug``), not counted as the command's warnings: the interruption made them."""
        old = sys.unraisablehook

        def hook(u) -> None:
            text = "".join(traceback.format_exception(u.exc_type, u.exc_value, u.exc_traceback))
            text = f"{u.err_msg or 'Exception ignored in'}: {u.object!r}\n{text}"
            if self.debug:
                sys.stderr.write(text)
            if self.log:
                warning_log.append(self.log, "after the interruption", text)

        sys.unraisablehook = hook
        try:
            seen: set[int] = set()
            while exc is not None and id(exc) not in seen:  # the exception and those it was raised during
                seen.add(id(exc))
                traceback.clear_frames(exc.__traceback__)  # finished frames' locals: their objects freed now
                exc = exc.__cause__ or exc.__context__
            gc.collect()  # and those in reference cycles
        finally:
            sys.unraisablehook = old
        if self.log and self.log.is_file():
            self.offset = self.log.stat().st_size

    def close(self) -> None:
        self.flush()
        if self._env is None:
            os.environ.pop(warning_log.ENV, None)
        else:
            os.environ[warning_log.ENV] = self._env


def config_data(a: argparse.Namespace) -> dict:
    """The YAML of ``--config``, read once per command ({} without one): a pipe (``--config /dev/stdin``)
    can be read only once."""
    if not hasattr(a, "_config_data"):
        from shaped_es.config import read_yaml

        a._config_data = read_yaml(a.config) if getattr(a, "config", None) else {}
    return a._config_data


def mpi_spawn_command(a: argparse.Namespace) -> bool:
    """True for train/resume/benchmark runs that would spawn MPI workers from this process."""
    if os.environ.get(_SUPERVISED) or a.command not in ("train", "resume", "benchmark"):
        return False
    executor = getattr(a, "executor", None)
    if executor is None and a.command == "resume":
        from shaped_es.rundir.store import RunStore

        executor = RunStore(a.run_dir).read_config().executor
    if executor is None and a.command == "train" and getattr(a, "config", None):
        executor = config_data(a).get("executor")
    if executor != "mpi":
        return False
    from shaped_es.executors.mpi_executor import under_mpiexec

    return not under_mpiexec()


_RELAYED = ("shaped-es:", "[train] ", "[ppo] ", "[benchmark] ")  # the command's own lines, progress included


def supervise(a: argparse.Namespace, argv: list[str], debug: bool) -> int:
    """Run the command in a child process and report, in one line, how it ended when MPI ended it.

    With spawned MPI workers, a worker that dies makes Open MPI end the trainer's process itself (exit
    14, after a few lines of MPI's own output). The child's stderr is relayed: its ``shaped-es:`` and
    progress lines as they come (all with ``--debug``); the rest goes to RUN/error.log (with one line
    saying so; to the terminal when there is no run directory), however the job ended; the child dies
    with this process."""
    env = {**os.environ, _SUPERVISED: "1"}

    def die_with_parent() -> None:  # pragma: no cover - runs in the child
        if sys.platform.startswith("linux"):
            import ctypes

            ctypes.CDLL(None).prctl(1, int(signal.SIGKILL))  # PR_SET_PDEATHSIG

    child = subprocess.Popen([sys.executable, "-m", "shaped_es.cli.commands", *argv], env=env,
                             stderr=subprocess.PIPE, text=True, errors="replace", preexec_fn=die_with_parent)
    old_int = signal.signal(signal.SIGINT, signal.SIG_IGN)  # the child gets the terminal's Ctrl-C
    old_term = signal.signal(signal.SIGTERM, lambda *_: child.terminate())
    other: list[str] = []
    try:
        for line in child.stderr:
            if debug or line.startswith(_RELAYED):
                sys.stderr.write(line)
                sys.stderr.flush()
            else:
                other.append(line)
        rc = child.wait()
    finally:
        signal.signal(signal.SIGINT, old_int)
        signal.signal(signal.SIGTERM, old_term)
    if rc in (0, INTERNAL_ERROR, USAGE_ERROR, 130):  # the child ended on its own: its other output too,
        path = _log(a, "".join(other)) if other else None  # into error.log (MPI's and its workers' lines)
        if path:
            print(f"shaped-es: warning: {len(other)} more lines of output from the MPI job (in {path})",
                  file=sys.stderr)
        else:
            sys.stderr.writelines(other)
        return rc
    where = _log_detail(a, "".join(other)) if other else ""
    how = f"signal {-rc}" if rc < 0 else f"exit {rc}"
    hint = continue_hint(a)
    print(f"shaped-es: error: the MPI job ended abruptly ({how}): a worker died or was killed, and MPI "
          f"cannot replace a lost rank{'; ' + hint if hint else ''}{where}", file=sys.stderr)
    return USAGE_ERROR
