"""MPI executor (the paper's engine): ``mpi4py.futures.MPIPoolExecutor`` behind the executor interface.

Two ways to get workers:

- **spawn** (``shaped-es train --executor mpi --workers N``): the master calls ``MPI_Comm_spawn`` to
  start N Python workers on this machine. MPI's byte traffic stays on the loopback interface
  (``OMPI_MCA_btl_tcp_if_include=lo`` unless already set), but this is **not** loopback-only: Open
  MPI's TCP transport (``btl/tcp``) binds its listening sockets to every interface by design, as does
  the ``prte`` launcher, and shared memory (``btl/sm``) cannot connect spawned jobs, so the listeners
  cannot be confined (constructing the executor warns once). On an untrusted network use ``process``
  or ``ray`` (whose laptop mode is loopback-only);
- **mpiexec** (a cluster, or a fixed allocation)::

      mpiexec -n 5 python -m mpi4py.futures -m shaped_es.cli.commands train --executor mpi ...

  rank 0 runs the trainer and ranks 1..4 are the workers (``workers`` is then the world size - 1).

Open MPI refuses to start as root unless told to; as root, export ``OMPI_ALLOW_RUN_AS_ROOT=1``,
``OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1``, ``PRTE_ALLOW_RUN_AS_ROOT=1`` and
``PRTE_ALLOW_RUN_AS_ROOT_CONFIRM=1`` (checked up front: otherwise spawn hangs).

Faults: MPI cannot replace a lost rank. With Open MPI's default error handler a worker that dies aborts
the whole job (the trainer's process exits with code 14), and a hung worker cannot be stopped from the
master. So this executor does not retry (``max_retries`` is kept only for a uniform signature): a task
past ``task_timeout_s`` raises :class:`ExecutorError`, and the job must be restarted (``shaped-es
resume`` continues from the last checkpoint). The command line runs spawn-mode jobs in a child process
and reports such an abort in one line with the resume command. Use ``--executor ray`` or ``process``
where workers may die.
"""

from __future__ import annotations

import os
import sys
import threading
import warnings
from collections.abc import Callable, Sequence
from concurrent.futures import Future, wait
from typing import Any

from shaped_es.executors.base import (Executor, ExecutorError, ExecutorWarning, check_local_workers,
                                      usable_cores)

ROOT_VARS = (
    "OMPI_ALLOW_RUN_AS_ROOT",
    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM",
    "PRTE_ALLOW_RUN_AS_ROOT",
    "PRTE_ALLOW_RUN_AS_ROOT_CONFIRM",
)
_LAUNCHER_VARS = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK")
_WORKER_ENV = {k: "1" for k in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")}


def under_mpiexec() -> bool:
    """True when this process was started by an MPI launcher (``mpiexec``/``srun``)."""
    return any(v in os.environ for v in _LAUNCHER_VARS)


def _prepare_spawn_env() -> None:
    if hasattr(os, "geteuid") and os.geteuid() == 0 and not all(os.environ.get(v) for v in ROOT_VARS):
        raise ExecutorError(
            "Open MPI refuses to run as root: export " + "=1 ".join(ROOT_VARS) + "=1 (or run as a user)"
        )
    # One machine: keep MPI's byte transfer on loopback. Its listeners still bind every interface.
    os.environ.setdefault("OMPI_MCA_btl_tcp_if_include", "lo")
    warnings.warn("MPI spawn mode: Open MPI's TCP transport and launcher listen on every network interface "
                  "(their traffic stays on loopback); on an untrusted network use --executor process or ray",
                  ExecutorWarning, stacklevel=4)


class MPIExecutor(Executor):
    """Map tasks over an ``MPIPoolExecutor``; results in task order; no retries (see module doc)."""

    def __init__(
        self,
        workers: int | None = None,
        max_retries: int = 0,
        task_timeout_s: float | None = None,
        startup_timeout_s: float = 120.0,
    ):
        self.max_retries = max_retries  # unused: MPI cannot replace a lost rank
        self.task_timeout_s = task_timeout_s
        spawn = not under_mpiexec()
        if spawn:
            _prepare_spawn_env()
        try:
            from mpi4py.futures import MPIPoolExecutor
        except ImportError as exc:
            raise ExecutorError(f"mpi4py cannot load MPI ({exc}): pip install 'shaped-es[mpi]'") from None
        opts: dict[str, Any] = {"main": False, "env": _WORKER_ENV, "path": [p for p in sys.path if p]}
        if spawn:
            opts["max_workers"] = int(workers or usable_cores())
            check_local_workers(opts["max_workers"], "mpi")
        self._pool = MPIPoolExecutor(**opts)
        self._broken = False
        self.workers = self._bootup(startup_timeout_s)

    def _bootup(self, timeout_s: float) -> int:
        """Start the workers; a launcher that never answers becomes an ExecutorError, not a hang."""
        box: dict[str, Any] = {}

        def run() -> None:
            try:
                box["n"] = self._pool.bootup(wait=True).num_workers
            except Exception as exc:  # noqa: BLE001 - reported below as one line
                box["err"] = exc

        t = threading.Thread(target=run, name="mpi-bootup", daemon=True)
        t.start()
        t.join(timeout_s)
        if "n" in box and box["n"] > 0:
            return int(box["n"])
        self._broken = True
        why = box.get("err") or f"no answer within {timeout_s:g} s"
        raise ExecutorError(f"MPI workers did not start: {why}")

    def submit(self, fn: Callable[[Any], Any], task: Any) -> Future:
        return self._pool.submit(fn, task)

    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any]) -> list[Any]:
        if self._broken:
            raise ExecutorError("the MPI executor is unusable after an earlier failure; restart the job")
        futures = [self._pool.submit(fn, t) for t in tasks]
        _, not_done = wait(futures, timeout=self.task_timeout_s)
        if not_done:
            self._broken = True
            raise ExecutorError(
                f"{len(not_done)} MPI task(s) still running after task_timeout_s={self.task_timeout_s:g}; "
                "MPI cannot replace a hung rank: restart the job (use ray/process for retries)"
            )
        from mpi4py.futures import BrokenExecutor

        try:
            return [f.result() for f in futures]
        except BrokenExecutor as exc:
            self._broken = True
            raise ExecutorError(f"MPI pool broke: {exc}") from None

    def shutdown(self) -> None:
        if self._pool is not None:
            if self._broken:
                self._pool.shutdown(wait=False, cancel_futures=True)
            else:
                self._pool.shutdown(wait=True)
            self._pool = None


__all__ = ["MPIExecutor", "ROOT_VARS", "under_mpiexec"]
