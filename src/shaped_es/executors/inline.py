"""Run every task in the calling process, one after another (debugging, tests, tiny runs)."""

from __future__ import annotations

from concurrent.futures import Future

from shaped_es.executors.base import Executor


class InlineExecutor(Executor):
    workers = 1
    in_process = True  # tasks run in the caller: their CPU time is the caller's

    def __init__(self, **_options):
        pass

    def submit(self, fn, task) -> Future:
        fut: Future = Future()
        try:
            fut.set_result(fn(task))
        except BaseException as exc:  # noqa: BLE001 - delivered through the future, like a pool would
            fut.set_exception(exc)
        return fut
