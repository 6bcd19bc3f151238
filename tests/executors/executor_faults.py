"""Fault injection for executor tests: task functions whose worker dies or hangs on a first attempt.

Which attempt is the first is decided by a marker file: the first call that creates it (``O_EXCL``,
atomic across processes and nodes of one machine) misbehaves; every later call, including the retry,
computes normally. Everything here is importable by worker processes (module-level, picklable).
"""

from __future__ import annotations

import os
import signal
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

from shaped_es.executors import Executor


def square(x: int) -> int:
    return x * x


def slow_square_with_pid(x: int) -> tuple[int, int]:
    time.sleep(0.3)  # long enough that concurrent tasks land on different workers
    return x * x, os.getpid()


def raise_on_three(x: int) -> int:
    if x == 3:
        raise ValueError("task three is broken")
    return x * x


def claim(marker: str) -> bool:
    """True for exactly one caller: the one that creates ``marker``."""
    try:
        os.close(os.open(marker, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
    except FileExistsError:
        return False
    return True


class LostServer(ConnectionError):
    """What an env raises when its simulator server stops answering (CarlaNav-v0's CarlaServerLost)."""

    worker_fault = True


def meet(folder: str, key: str, n: int, give_up_s: float = 120.0) -> str:
    """Sign in as ``key`` in ``folder`` and wait until ``n`` distinct keys have (or ``give_up_s``); ``key``.

    Concurrent tasks that each wait here until ``n`` different workers (or nodes) have signed in land on
    ``n`` different ones whatever the machine's speed: a worker busy in one such task cannot take
    another, so the others must (a sleep only makes that likely, and not on a loaded machine)."""
    open(os.path.join(folder, key), "a").close()
    deadline = time.monotonic() + give_up_s
    while len(os.listdir(folder)) < n and time.monotonic() < deadline:
        time.sleep(0.01)
    return key


@dataclass
class WorkerIndex:
    """The worker's ``$SHAPED_ES_WORKER_INDEX``, once ``n`` workers run such a task (:func:`meet`)."""

    folder: str  # an empty folder per map
    n: int

    def __call__(self, _: object) -> str | None:
        index = os.environ.get("SHAPED_ES_WORKER_INDEX")
        return meet(self.folder, str(index), self.n)


def misbehave(mode: str) -> None:
    if mode == "fault":
        raise LostServer("the simulator server stopped answering")
    if mode == "exit":
        os._exit(13)  # the worker process dies without a word
    if mode == "kill":
        os.kill(os.getpid(), signal.SIGKILL)
    if mode == "hang":
        while True:
            time.sleep(60)
    raise ValueError(f"unknown mode {mode!r}")


@dataclass
class FailOnce:
    """Call ``fn``, except that the first matching call (claims ``marker``) dies or hangs."""

    fn: Callable[[Any], Any]
    marker: str  # path of the marker file (absent before the run)
    mode: str = "exit"  # exit | kill | hang | fault (raise a worker fault)
    only_value: Any = None  # only tasks equal to this may fail (plain values)
    generation: int | None = None  # only RolloutTasks of this generation may fail

    def _matches(self, task: Any) -> bool:
        if self.generation is not None:
            return getattr(task, "generation", None) == self.generation
        return self.only_value is None or task == self.only_value

    def __call__(self, task: Any) -> Any:
        if self._matches(task) and claim(self.marker):
            misbehave(self.mode)
        return self.fn(task)


@dataclass
class FailAlways:
    """Every call dies (retries must run out)."""

    mode: str = "exit"

    def __call__(self, task: Any) -> Any:
        misbehave(self.mode)


class FaultyExecutor(Executor):
    """Wraps an executor so that one task of one generation's training map loses its worker."""

    def __init__(self, inner: Executor, marker: str, generation: int, mode: str = "exit"):
        self.inner, self.marker, self.generation, self.mode = inner, marker, generation, mode
        self.workers = inner.workers

    def submit(self, fn, task):
        return self.inner.submit(fn, task)

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any]) -> list[Any]:
        return self.inner.map(FailOnce(fn, self.marker, self.mode, generation=self.generation), tasks)

    def shutdown(self) -> None:
        self.inner.shutdown()


@dataclass
class SquareOnNode:
    """(x*x, id of the Ray node that ran it), once ``n`` nodes run such a task (:func:`meet`)."""

    folder: str  # an empty folder per map
    n: int

    def __call__(self, x: int) -> tuple[int, str]:
        import ray

        return x * x, meet(self.folder, ray.get_runtime_context().get_node_id(), self.n)
