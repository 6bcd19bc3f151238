"""The executor interface: map tasks over workers, in order, retrying tasks whose worker died.

Executors only place work; what a task computes is a plain function of its argument. Because every
seed is part of the task (``seeding.py``), a retried task reproduces the result of the lost one.
"""

from __future__ import annotations

import os
import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from concurrent.futures import Future
from typing import Any


class ExecutorError(RuntimeError):
    """Tasks could not be completed (retries exhausted, or the backend is unavailable)."""


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

    def shutdown(self) -> None:  # noqa: B027 - optional for executors with nothing to release
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.shutdown()
        return False
