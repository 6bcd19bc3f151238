"""Run every task in the calling process, one after another (debugging, tests, tiny runs)."""

from __future__ import annotations

import warnings
from concurrent.futures import Future

from shaped_es.executors.base import Executor, ExecutorWarning


class InlineExecutor(Executor):
    """No faults to handle: a task that raises raises in the caller, and ``task_timeout_s`` cannot
    apply (nothing can stop a task running in the caller's own thread): setting it warns."""

    workers = 1
    in_process = True  # tasks run in the caller: their CPU time is the caller's

    def __init__(self, task_timeout_s: float | None = None, **_options):
        if task_timeout_s is not None:
            warnings.warn(f"task_timeout_s={task_timeout_s:g} cannot apply to the inline executor (tasks run "
                          f"in the trainer's own thread); use --executor process to cut off hung tasks",
                          ExecutorWarning, stacklevel=3)

    def submit(self, fn, task) -> Future:
        fut: Future = Future()
        try:
            fut.set_result(fn(task))
        except BaseException as exc:  # noqa: BLE001 - delivered through the future, like a pool would
            fut.set_exception(exc)
        return fut
