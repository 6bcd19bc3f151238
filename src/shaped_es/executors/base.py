"""The executor interface: map tasks over workers, in order, retrying tasks whose worker died.

Executors only place work; what a task computes is a plain function of its argument. Because every
seed is part of the task (``seeding.py``), a retried task reproduces the result of the lost one.
"""

from __future__ import annotations

import os
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from concurrent.futures import CancelledError, Future, wait
from typing import Any


class ExecutorError(RuntimeError):
    """Tasks could not be completed (retries exhausted, or the backend is unavailable). The message is
    one line; ``detail`` holds what the backend printed meanwhile (for a log file)."""

    def __init__(self, message: str = "", detail: str = ""):
        super().__init__(message)
        self.detail = detail

    def __reduce__(self):  # crosses process boundaries with its detail
        return type(self), (str(self), self.detail)


class ExecutorWarning(UserWarning):
    """A setting that cannot apply, or looks wrong (the command line prints it as one line)."""


# Each process-executor worker gets a stable index 0..workers-1 in this environment variable (a new pool
# numbers its workers again); inline, Ray and MPI workers do not set it (index 0). An env that needs
# one resource per worker (CarlaNav-v0: one CARLA server) picks it by this index.
WORKER_INDEX_ENV = "SHAPED_ES_WORKER_INDEX"


def is_worker_fault(exc: BaseException) -> bool:
    """True if a task raised an exception that marks its worker's resource as lost (``worker_fault =
    True``, e.g. CarlaNav-v0's lost server): a fault of the worker, not of the task."""
    return bool(getattr(exc, "worker_fault", False))


MAX_LOCAL_WORKERS = 1024  # processes on one machine; more is refused, more than 4 per core warned about


def usable_cores() -> int:
    """The cores this process may run on: its CPU affinity where the OS has one (``taskset``, a cgroup's cpuset,
    a batch scheduler's allocation), else ``os.cpu_count()``. The process executor's default workers and the
    clones' threads count these, so ``taskset -c 0 shaped-es ...`` holds a run to one core."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # macOS, Windows
        return os.cpu_count() or 1


def check_local_workers(workers: int, executor: str) -> None:
    """Refuse a worker count no machine runs as local processes; warn above 4 per core."""
    import warnings

    cpus = usable_cores()
    if workers > MAX_LOCAL_WORKERS:
        raise ExecutorError(f"--workers {workers} is more than {MAX_LOCAL_WORKERS} local {executor} workers "
                            f"(this machine has {cpus} cores); use --executor ray on a cluster")
    if workers > 4 * cpus:
        warnings.warn(f"--workers {workers} starts {workers} {executor} workers on {cpus} cores (more than "
                      f"4 per core only adds overhead)", ExecutorWarning, stacklevel=3)


def pid_after(delay_s: float) -> int:
    """Warm-up probe: the worker's pid after a short sleep (so one call cannot serve every probe)."""
    time.sleep(delay_s)
    return os.getpid()


class Executor(ABC):
    """``concurrent.futures``-style: ``submit`` returns a Future; ``map`` returns results in task order."""

    workers: int = 1

    @abstractmethod
    def submit(self, fn: Callable[[Any], Any], task: Any) -> Future: ...

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any]) -> list[Any]:
        futures = [self.submit(fn, t) for t in tasks]
        return [f.result() for f in futures]

    # -- fault handling for submitted tasks (the trainer's test episodes) ---------------------------
    task_timeout_s: float | None = None

    def _is_fault(self, exc: BaseException) -> bool:
        """True if ``exc`` (from a submitted task's future) means its worker was lost, not that the task
        itself raised."""
        return False

    def _raise_task_error(self, exc: BaseException) -> None:
        """Raise what ``fn`` itself raised (a backend may wrap it)."""
        raise exc

    def _abandon(self, futures: Sequence[Future]) -> None:  # noqa: B027 - nothing to stop by default
        """Stop attempts that are past their timeout (their workers may be hung)."""

    def collect(self, fn: Callable[[Any], Any], tasks: Sequence[Any], futures: Sequence[Future]) -> list[Any]:
        """Results of ``tasks`` submitted earlier (``futures[i] = submit(fn, tasks[i])``), in order, with
        ``map``'s fault handling: attempts that lost their worker, were cancelled, or are still running
        ``task_timeout_s`` after this call are abandoned and run again through ``map`` (which retries
        and times out in turn). An exception raised by ``fn`` itself propagates unchanged."""
        _, not_done = wait(futures, timeout=self.task_timeout_s)
        results: dict[int, Any] = {}
        redo: list[int] = []
        for i, f in enumerate(futures):
            if f in not_done:
                redo.append(i)
                continue
            try:
                results[i] = f.result()
            except CancelledError:
                redo.append(i)
            except Exception as exc:
                if not self._is_fault(exc):
                    self._raise_task_error(exc)
                redo.append(i)
        if not_done:
            self._abandon(list(not_done))
        if redo:
            for i, r in zip(redo, self.map(fn, [tasks[i] for i in redo])):
                results[i] = r
        return [results[i] for i in range(len(tasks))]

    def shutdown(self) -> None:  # noqa: B027 - optional for executors with nothing to release
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.shutdown()
        return False
