"""Local worker processes (the default executor): a spawn/forkserver pool, one BLAS/torch thread each.

If a worker dies (a crashing simulator, the OOM killer), the pool is rebuilt and every task that had
not finished is submitted again, up to ``max_retries`` times; a task that runs longer than
``task_timeout_s`` is treated the same way. Seeds travel inside tasks, so a retry gives the result the
lost attempt would have given. A new pool starts all its workers before tasks are submitted, so the
timeout never counts process start-up; an exception raised by the task function itself propagates.
Tasks started with ``submit`` get the same treatment through ``collect``.

A Ctrl-C while the pool starts or works ends the run with the trainer's one line only: a worker ignores
SIGINT (blocked from its birth until then), and a Ctrl-C while the pool starts its workers takes effect
once all are started (so ``shutdown`` ends them).

Workers never outlive the process that started them: each one is killed when its parent (the
forkserver, which exits with the trainer) dies (Linux ``PR_SET_PDEATHSIG``), and a watchdog thread ends
it within a second of the trainer's death elsewhere, even while a task hangs inside ``env.step``.

Each worker of a pool has a stable index ``first_index``..``first_index + workers - 1`` (0 first) in
``$SHAPED_ES_WORKER_INDEX`` (``base.WORKER_INDEX_ENV``; a rebuilt pool numbers its workers again; the
trainer's separate evaluation pool starts after the training workers), so an env can pick a resource per worker (CarlaNav-v0: the
server at ``port + 3 * index``). A task that raises a worker fault (``base.is_worker_fault``: a lost
simulator server) is not retried here: it propagates and the run stops with one line and the resume command.
"""

from __future__ import annotations

import contextlib
import multiprocessing as mp
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from shaped_es.monitor import warning_log
from shaped_es.executors.base import (WORKER_INDEX_ENV, Executor, ExecutorError, check_local_workers, pid_after,
                                      usable_cores)

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


def _init_worker(owner_pid: int | None = None, counter=None, warning_log_path: str | None = None) -> None:
    # Ctrl-C reaches the terminal's whole process group: the trainer handles it (one line and the resume
    # command; ``shutdown`` then ends the workers), so a worker ignores it instead of printing a
    # KeyboardInterrupt traceback from wherever it was waiting. It was born with SIGINT blocked
    # (_starting_workers), so a Ctrl-C during its start-up waited, pending, and is dropped here.
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})  # ignored from now on, not held back
    # One BLAS/OpenMP/Numba/torch thread per worker. torch reads OMP_NUM_THREADS when a task first
    # imports it, so a worker pays torch's import (seconds) only if a task needs torch.
    warning_log.to_log(warning_log_path)  # other libraries' warnings: the run's error.log, not the terminal
    for var in _THREAD_VARS:
        os.environ[var] = "1"
    if counter is not None:  # the pool's shared counter: this worker's index (0..workers-1)
        with counter.get_lock():
            os.environ[WORKER_INDEX_ENV] = str(counter.value)
            counter.value += 1
    torch = sys.modules.get("torch")
    if torch is not None:
        torch.set_num_threads(1)
    if owner_pid is not None:
        die_with(owner_pid)


@contextlib.contextmanager
def _starting_workers():
    """The pool's processes are started inside this block. Each is born with SIGINT blocked (the mask of
    the thread that starts it), so a Ctrl-C during its start-up (``site``, imports, before
    :func:`_init_worker` ignores SIGINT) prints no traceback from it; in the main thread, a Ctrl-C (or
    SIGTERM) that comes meanwhile takes effect at the end of the block, once the pool knows every worker
    it started and ``shutdown`` can end them (a worker started while the trainer already cleaned up
    would fail on its pool's semaphores, gone by then, with a traceback)."""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()  # first: starting it unblocks SIGINT in this thread when it returns
    came: list[int] = []
    held = (signal.SIGINT, signal.SIGTERM)
    old = {s: signal.getsignal(s) for s in held} if threading.current_thread() is threading.main_thread() else {}
    old = {s: h for s, h in old.items() if h is not None}  # None: a handler not set from Python, left alone
    for s in old:
        signal.signal(s, lambda signum, frame: came.append(signum))
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)
        for s, h in old.items():
            signal.signal(s, h)
        if came:
            signal.raise_signal(came[0])  # now, to the handler it would have reached


def _gone(pid: int) -> bool:
    """True if ``pid`` no longer runs (a zombie counts as gone: killed, not yet reaped)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            return fh.read().rsplit(b")", 1)[1].split()[0] in (b"Z", b"X")
    except (OSError, IndexError):
        return False


def die_with(owner_pid: int, period_s: float = 0.5) -> None:
    """End this process when ``owner_pid`` (the trainer) or this process's parent dies, even while the
    main thread is stuck in a task (a daemon thread checks every ``period_s``; on Linux the kernel also
    kills it when its parent exits)."""
    if sys.platform.startswith("linux") and os.getppid() != owner_pid:  # parent: the forkserver
        try:
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(1, int(signal.SIGKILL))  # 1 = PR_SET_PDEATHSIG
        except (OSError, AttributeError):  # pragma: no cover
            pass
    parent = os.getppid()

    def watch() -> None:
        while True:
            time.sleep(period_s)
            if os.getppid() != parent or _gone(owner_pid):
                os._exit(70)

    threading.Thread(target=watch, name="owner-watch", daemon=True).start()


class ProcessExecutor(Executor):
    def __init__(
        self,
        workers: int | None = None,
        start_method: str = "forkserver",
        max_retries: int = 3,
        task_timeout_s: float | None = None,
        startup_timeout_s: float = 120.0,
        first_index: int = 0,
    ):
        self.workers = int(workers or usable_cores())
        self.first_index = int(first_index)  # worker indices are first_index .. first_index + workers - 1
        check_local_workers(self.workers, "process")
        if start_method not in ("spawn", "forkserver"):
            raise ExecutorError(f"start_method must be 'spawn' or 'forkserver', got {start_method!r}")
        self.start_method = start_method
        self.max_retries = max_retries
        self.task_timeout_s = task_timeout_s  # counted from submission to a started pool
        self.startup_timeout_s = startup_timeout_s  # longest wait for all workers to come up
        self.restarts = 0  # pools rebuilt after a dead worker or a timeout
        self.retries = 0  # task resubmissions
        self._pool: ProcessPoolExecutor | None = None

    def _get_pool(self) -> ProcessPoolExecutor:
        if self._pool is None:
            from shaped_es.executors.main_guard import exit_if_unguarded

            exit_if_unguarded(written=True)  # an unguarded script: its workers would run it again
            # Children inherit the environment at start: one BLAS/OpenMP/Numba thread per worker.
            for var in _THREAD_VARS:
                os.environ.setdefault(var, "1")
            ctx = mp.get_context(self.start_method)
            self._pool = ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=_init_worker,
                                             initargs=(os.getpid(), ctx.Value("i", self.first_index),
                                                       os.environ.get(warning_log.ENV)))
            self._warm_up(self._pool)
        return self._pool

    def _warm_up(self, pool: ProcessPoolExecutor) -> None:
        """Start every worker before any task is timed, so ``task_timeout_s`` never counts start-up."""
        seen: set[int] = set()
        deadline = time.monotonic() + self.startup_timeout_s
        while len(seen) < self.workers:
            with _starting_workers():  # submit starts the workers (and the forkserver), not awaiting their start-up
                futures = [pool.submit(pid_after, 0.02) for _ in range(self.workers)]
            try:
                seen.update(f.result(timeout=max(0.0, deadline - time.monotonic())) for f in futures)
            except TimeoutError:
                raise ExecutorError(
                    f"worker processes did not start within {self.startup_timeout_s:g} s"
                ) from None

    def _reset_pool(self) -> None:
        if self._pool is not None:
            for p in list(getattr(self._pool, "_processes", {}).values()):
                if p.is_alive():
                    p.kill()
            self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = None
        self.restarts += 1

    def submit(self, fn: Callable[[Any], Any], task: Any) -> Future:
        try:
            return self._get_pool().submit(fn, task)
        except BrokenProcessPool:  # a worker died while the pool sat idle: a new pool takes it
            self._reset_pool()
            return self._get_pool().submit(fn, task)

    def _is_fault(self, exc: BaseException) -> bool:
        return isinstance(exc, BrokenProcessPool)

    def _abandon(self, futures) -> None:
        self.retries += len(futures)
        self._reset_pool()  # the only way to stop a hung task: its worker goes with the pool

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any]) -> list[Any]:
        """Results in task order. Each round submits the unfinished tasks; a dead worker or a round
        running past ``task_timeout_s`` (counted from submission) rebuilds the pool for the next round.
        An exception raised by ``fn`` itself propagates unchanged."""
        results: dict[int, Any] = {}
        pending = list(range(len(tasks)))
        why = ""
        for _ in range(self.max_retries + 1):
            if not pending:
                break
            try:
                pool = self._get_pool()
                futures = {pool.submit(fn, tasks[i]): i for i in pending}
            except BrokenProcessPool:  # a worker died while the pool sat idle
                self._reset_pool()
                why = "worker died"
                continue
            done, not_done = wait(futures, timeout=self.task_timeout_s)
            why = f"timed out after {self.task_timeout_s:g} s" if not_done else "worker died"
            for fut in done:
                try:
                    results[futures[fut]] = fut.result()
                except BrokenProcessPool:
                    pass
            pending = [i for i in pending if i not in results]
            if pending:
                self.retries += len(pending)
                self._reset_pool()
        if pending:
            raise ExecutorError(
                f"{len(pending)} task(s) failed {self.max_retries + 1} time(s), last: {why}; giving up "
                f"(max_retries={self.max_retries})"
            )
        return [results[i] for i in range(len(tasks))]

    def shutdown(self) -> None:
        if self._pool is not None:
            if getattr(self._pool, "_pending_work_items", None):  # interrupted or failed mid-map: tasks still
                for p in list(getattr(self._pool, "_processes", {}).values()):  # running are not waited for
                    if p.is_alive():
                        p.kill()
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
