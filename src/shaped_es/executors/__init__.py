"""Executors: place tasks on workers (in-process, local processes, Ray, MPI). See ``base.Executor``.

``ray`` and ``mpi`` are optional extras, imported only when asked for, so the package works without
them: ``pip install 'shaped-es[ray]'`` / ``'shaped-es[mpi]'``.
"""

from __future__ import annotations

from collections.abc import Callable

from shaped_es.executors.base import Executor, ExecutorError, ExecutorWarning
from shaped_es.executors.inline import InlineExecutor
from shaped_es.executors.process import ProcessExecutor


def _require(module: str, extra: str) -> None:
    import importlib.util

    if importlib.util.find_spec(module) is None:
        raise ExecutorError(f"{module} is not installed: pip install 'shaped-es[{extra}]'")


def _ray(workers: int | None = None, **options) -> Executor:
    _require("ray", "ray")
    from shaped_es.executors.ray_executor import RayExecutor

    return RayExecutor(workers=workers, **options)


def _mpi(workers: int | None = None, **options) -> Executor:
    _require("mpi4py", "mpi")
    from shaped_es.executors.mpi_executor import MPIExecutor

    return MPIExecutor(workers=workers, **options)


# The one registry of executors: name -> factory ``(workers=None, **options) -> Executor``. The run config's
# ``executor`` field, the CLI's ``--executor`` choices and ``make_executor`` all read it; a new executor is
# its file plus one entry here. Optional extras (ray, mpi) are imported only when built.
EXECUTORS: dict[str, Callable[..., Executor]] = {
    "inline": InlineExecutor,  # ignores ``workers`` (one, the caller)
    "process": ProcessExecutor,
    "ray": _ray,
    "mpi": _mpi,
}


def make_executor(name: str, workers: int | None = None, **options) -> Executor:
    """Build an executor by name (one of :data:`EXECUTORS`).

    ``inline`` and ``process`` take ``max_retries``/``task_timeout_s`` (inline cannot apply them: a
    timeout warns); ``ray``
    also takes ``address`` (None: private local Ray; ``"auto"`` or ``HOST:PORT``: a running cluster);
    ``mpi`` takes ``task_timeout_s`` (see ``mpi_executor`` for launching).
    """
    try:
        factory = EXECUTORS[name]
    except KeyError:
        raise ExecutorError(f"unknown executor {name!r}; choose one of {', '.join(EXECUTORS)}") from None
    return factory(workers=workers, **options)


__all__ = ["EXECUTORS", "Executor", "ExecutorError", "ExecutorWarning", "InlineExecutor", "ProcessExecutor",
           "make_executor"]
