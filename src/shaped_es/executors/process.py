"""Local worker processes (the default executor): a spawn/forkserver pool, one BLAS/torch thread each.

If a worker dies (a crashing simulator, the OOM killer), the pool is rebuilt and every task that had
not finished is submitted again, up to ``max_retries`` times; a task that runs longer than
``task_timeout_s`` is treated the same way. Seeds travel inside tasks, so a retry gives the result the
lost attempt would have given.
"""

from __future__ import annotations

import multiprocessing as mp
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any

from shaped_es.executors.base import Executor, ExecutorError

_THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")


def _init_worker() -> None:
    try:
        import torch

        torch.set_num_threads(1)
    except ImportError:  # pragma: no cover - torch is a dependency
        pass


class ProcessExecutor(Executor):
    def __init__(
        self,
        workers: int | None = None,
        start_method: str = "forkserver",
        max_retries: int = 3,
        task_timeout_s: float | None = None,
    ):
        self.workers = int(workers or os.cpu_count() or 1)
        if start_method not in ("spawn", "forkserver"):
            raise ExecutorError(f"start_method must be 'spawn' or 'forkserver', got {start_method!r}")
        self.start_method = start_method
        self.max_retries = max_retries
        self.task_timeout_s = task_timeout_s
        self.restarts = 0
        self._pool: ProcessPoolExecutor | None = None

    def _get_pool(self) -> ProcessPoolExecutor:
        if self._pool is None:
            # Children inherit the environment at start: one BLAS/OpenMP/Numba thread per worker.
            for var in _THREAD_VARS:
                os.environ.setdefault(var, "1")
            ctx = mp.get_context(self.start_method)
            self._pool = ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=_init_worker)
        return self._pool

    def _reset_pool(self) -> None:
        if self._pool is not None:
            for p in list(getattr(self._pool, "_processes", {}).values()):
                if p.is_alive():
                    p.kill()
            self._pool.shutdown(wait=False, cancel_futures=True)
        self._pool = None
        self.restarts += 1

    def submit(self, fn: Callable[[Any], Any], task: Any) -> Future:
        return self._get_pool().submit(fn, task)

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any]) -> list[Any]:
        results: dict[int, Any] = {}
        pending = list(range(len(tasks)))
        for attempt in range(self.max_retries + 1):
            pool = self._get_pool()
            futures = {pool.submit(fn, tasks[i]): i for i in pending}
            done, not_done = wait(futures, timeout=self.task_timeout_s)
            broken = bool(not_done)
            for fut in done:
                try:
                    results[futures[fut]] = fut.result()
                except BrokenProcessPool:
                    broken = True
            pending = [i for i in pending if i not in results]
            if not pending:
                return [results[i] for i in range(len(tasks))]
            if broken:
                self._reset_pool()
        raise ExecutorError(
            f"{len(pending)} task(s) failed after {self.max_retries} retries (worker died or timed out)"
        )

    def shutdown(self) -> None:
        if self._pool is not None:
            self._pool.shutdown(wait=True, cancel_futures=True)
            self._pool = None
