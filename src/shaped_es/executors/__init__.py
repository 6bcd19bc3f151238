"""Executors: place tasks on workers (in-process, local processes, Ray, MPI). See ``base.Executor``.

``ray`` and ``mpi`` are optional extras, imported only when asked for, so the package works without
them: ``pip install 'shaped-es[ray]'`` / ``'shaped-es[mpi]'``.
"""

from __future__ import annotations

from shaped_es.executors.base import Executor, ExecutorError, ExecutorWarning
from shaped_es.executors.inline import InlineExecutor
from shaped_es.executors.process import ProcessExecutor

EXECUTORS = ("inline", "process", "ray", "mpi")


def _require(module: str, extra: str) -> None:
    import importlib.util

    if importlib.util.find_spec(module) is None:
        raise ExecutorError(f"{module} is not installed: pip install 'shaped-es[{extra}]'")


def make_executor(name: str, workers: int | None = None, **options) -> Executor:
    """Build an executor by name.

    ``inline`` and ``process`` take ``max_retries``/``task_timeout_s`` (inline cannot apply them: a
    timeout warns); ``ray``
    also takes ``address`` (None: private local Ray; ``"auto"`` or ``HOST:PORT``: a running cluster);
    ``mpi`` takes ``task_timeout_s`` (see ``mpi_executor`` for launching).
    """
    if name == "inline":
        return InlineExecutor(**options)
    if name == "process":
        return ProcessExecutor(workers=workers, **options)
    if name == "ray":
        _require("ray", "ray")
        from shaped_es.executors.ray_executor import RayExecutor

        return RayExecutor(workers=workers, **options)
    if name == "mpi":
        _require("mpi4py", "mpi")
        from shaped_es.executors.mpi_executor import MPIExecutor

        return MPIExecutor(workers=workers, **options)
    raise ExecutorError(f"unknown executor {name!r}; choose one of {', '.join(EXECUTORS)}")


__all__ = ["EXECUTORS", "Executor", "ExecutorError", "ExecutorWarning", "InlineExecutor", "ProcessExecutor",
           "make_executor"]
