"""Executors: place tasks on workers (in-process, local processes, Ray). See ``base.Executor``."""

from __future__ import annotations

from shaped_es.executors.base import Executor, ExecutorError
from shaped_es.executors.inline import InlineExecutor
from shaped_es.executors.process import ProcessExecutor

EXECUTORS = ("inline", "process")


def make_executor(name: str, workers: int | None = None, **options) -> Executor:
    """Build an executor by name: ``inline`` or ``process`` (more register as they land)."""
    if name == "inline":
        return InlineExecutor(**options)
    if name == "process":
        return ProcessExecutor(workers=workers, **options)
    raise ExecutorError(f"unknown executor {name!r}; choose one of {', '.join(EXECUTORS)}")


__all__ = ["Executor", "ExecutorError", "InlineExecutor", "ProcessExecutor", "make_executor"]
