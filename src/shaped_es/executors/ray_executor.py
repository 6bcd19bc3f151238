"""Ray executor: the same generation loop on a Ray cluster, or on a private local Ray (laptop mode).

The paper runs its ES workers under MPI on a cluster; this is the fault-tolerant way to do the same.
Workers only roll out parameter chunks (the master's ``strategy.ask``/``tell`` stays in the caller).

Two modes:

- ``address=None`` (laptop mode) starts a *private* local Ray for this process, never attaching to a
  cluster that happens to run on the machine: ``address="local"``, ``num_cpus=workers``, no dashboard,
  every Ray process bound to the loopback address 127.0.0.1, worker output not forwarded, quiet logs.
  The Ray is stopped by :meth:`RayExecutor.shutdown`.
- ``address="auto"`` or ``"HOST:PORT"`` (cluster mode) attaches to a running cluster (``ray start``);
  ``workers`` defaults to the cluster's CPU count. ``shutdown`` only disconnects.

Data movement per ``map(fn, tasks)``: ``fn`` is put into the object store once (it may carry shared
state, e.g. model weights in a ``functools.partial``) and every task once; the remote calls get object
references, so a retry ships nothing again. The trainer's tasks are disjoint population chunks, one per
worker, so the population matrix travels exactly once. Only the small result summaries come back
(per-step transitions too when a task records them).

Faults (``max_retries``, ``task_timeout_s``; ``collect`` applies them to tasks from ``submit`` too): a
task whose worker process or node died is resubmitted;
a task still running ``task_timeout_s`` after its submission is force-cancelled, which kills its worker,
and resubmitted. Worker start-up never counts against the timeout: the executor starts its workers
before the first map, and a replacement worker before each retry. Seeds travel inside tasks, so a
retry reproduces the lost result. A task that fails ``max_retries + 1`` times raises
:class:`ExecutorError`; an exception raised *by the task function* is not a fault and propagates
unchanged (with the remote traceback as its ``__cause__``), except a *worker fault* (an exception with
``worker_fault = True``, ``base.is_worker_fault``: CarlaNav-v0's lost server), which is retried like a
lost worker. Ray workers have no ``$SHAPED_ES_WORKER_INDEX`` (index 0): one task slot per node.
"""

from __future__ import annotations

import logging
import math
import os
import socket
import sys
import tempfile
import time
import warnings
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import Future
from contextlib import contextmanager, nullcontext
from typing import Any

import ray
import ray.exceptions as rex

from shaped_es.executors.base import Executor, ExecutorError, is_worker_fault, pid_after, usable_cores

LOOPBACK = "127.0.0.1"

# Faults that a resubmission can cure (the task itself did not raise).
_RETRYABLE = (
    rex.WorkerCrashedError,  # the worker process died (os._exit, segfault, OOM killer, force-cancel)
    rex.NodeDiedError,  # the node running it went away
    rex.ObjectLostError,  # an argument or the result was lost with a node (and its subclasses)
    rex.OutOfMemoryError,  # Ray's memory monitor killed the worker
    rex.TaskCancelledError,  # cancelled by someone else
    rex.RaySystemError,
)


def _apply(fn: Callable[[Any], Any], task: Any) -> Any:
    return fn(task)


# One CPU per task; retries are ours (uniform counting with timeouts), so Ray's are off.
_remote_apply = ray.remote(num_cpus=1, max_retries=0, retry_exceptions=False)(_apply)
_remote_pid = ray.remote(num_cpus=1, max_retries=0)(pid_after)


@contextmanager
def _loopback_node_ip() -> Iterator[None]:
    """Let Ray keep 127.0.0.1 as the node address while a local instance starts.

    Ray replaces a loopback ``_node_ip_address`` with the machine's routable address unless cluster
    support is off (its own macOS/Windows laptop default, env ``RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER=0``,
    read once at import). We switch it off only for the duration of ``ray.init``; :func:`_start_local`
    then checks the address Ray actually used.
    """
    import ray._private.ray_constants as rc

    if not hasattr(rc, "ENABLE_RAY_CLUSTER"):  # another Ray version: the address check still guards
        yield
        return
    old, rc.ENABLE_RAY_CLUSTER = rc.ENABLE_RAY_CLUSTER, False
    try:
        yield
    finally:
        rc.ENABLE_RAY_CLUSTER = old


@contextmanager
def _ray_output() -> Iterator[list[str]]:
    """Catch what Ray's C++ core writes to file descriptor 2 while it connects to a cluster (a line a
    second from ``gcs_client.cc`` while an address does not answer): the list gets the text at the end.
    A failure carries it as its ``ExecutorError.detail`` (RUN/error.log); after a success it becomes one
    warning, which the command line also sends there. (Not around a local start: the Ray processes it
    spawns would inherit the descriptor.)"""
    out: list[str] = []
    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield out
        finally:
            sys.stderr.flush()
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            out.append(tmp.read().decode("utf-8", "replace"))


def _init(what: str, **kwargs) -> None:
    """``ray.init(**kwargs)`` with Ray's own output caught (``_ray_output``); ``what`` names the
    address in the one-line ``ExecutorError`` a failure raises."""
    caught: list[str] = []
    try:
        with _ray_output() as caught:
            ray.init(**kwargs)
    except (ConnectionError, RuntimeError, ValueError) as exc:
        msg = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise ExecutorError(f"{what}: {msg}", detail="".join(caught)) from None
    text = "".join(caught).strip()
    if text:
        warnings.warn_explicit(f"Ray's output while connecting: {text}", UserWarning, "ray", 0)


def _start_local(workers: int) -> None:
    """Start a private, loopback-only, quiet local Ray with ``workers`` CPUs."""
    os.environ.setdefault("RAY_USAGE_STATS_ENABLED", "0")  # no usage reports leave the machine
    os.environ.setdefault("RAY_USAGE_STATS_PROMPT_ENABLED", "0")
    with _loopback_node_ip():
        ray.init(
            address="local",  # always a new instance: never attach to a cluster found on the machine
            num_cpus=workers,
            include_dashboard=False,
            _node_ip_address=LOOPBACK,
            log_to_driver=False,
            logging_level=logging.ERROR,
        )
    ip = ray.util.get_node_ip_address()
    if ip != LOOPBACK:  # pragma: no cover - guards against a Ray version that ignores the request
        ray.shutdown()
        raise ExecutorError(f"local Ray bound {ip} instead of {LOOPBACK}; refusing to run")


def _is_loopback(address: str) -> bool:
    host = address.rsplit(":", 1)[0].strip("[]")
    return host == "localhost" or host == "::1" or host.startswith("127.")


def _check_answers(address: str, timeout_s: float = 10.0) -> None:
    """``ExecutorError`` at once if nothing accepts a connection at ``HOST:PORT`` (``ray.init`` would
    retry a refused address for minutes); ``auto`` and other forms are left to Ray."""
    host, _, port = address.split("://", 1)[-1].rpartition(":")
    if not host or not port.isdigit():
        return
    try:
        socket.create_connection((host.strip("[]"), int(port)), timeout=timeout_s).close()
    except OSError as exc:
        why = exc.strerror or type(exc).__name__
        raise ExecutorError(f"cannot connect to Ray at {address!r}: nothing answers there ({why})") from None


def _connect(address: str) -> None:
    """Attach to a running cluster (a loopback address keeps this driver on loopback too)."""
    _check_answers(address)
    pin = _loopback_node_ip() if _is_loopback(address) else nullcontext()
    with pin:
        _init(f"cannot connect to Ray at {address!r}", address=address, log_to_driver=False,
              logging_level=logging.ERROR)


class RayExecutor(Executor):
    """Map tasks over Ray workers in order, with per-task retries and timeouts.

    ``workers``: task slots (laptop mode: the local Ray's CPUs, default all cores; cluster mode: the
    cluster's CPUs unless given). ``address``: None (private local Ray), ``"auto"`` or ``HOST:PORT``.
    """

    def __init__(
        self,
        workers: int | None = None,
        address: str | None = None,
        max_retries: int = 3,
        task_timeout_s: float | None = None,
        startup_timeout_s: float = 120.0,
    ):
        self.address = address
        self.max_retries = int(max_retries)
        self.task_timeout_s = task_timeout_s  # from submission to a started worker
        self.startup_timeout_s = startup_timeout_s  # longest wait for worker processes to come up
        self.retries = 0  # tasks resubmitted so far (worker deaths + timeouts)
        self._owns_ray = False  # we started/connected Ray and must shut it down
        if ray.is_initialized():
            if address is None:
                raise ExecutorError(
                    "Ray is already initialized in this process; pass --address (e.g. 'auto') to use it"
                )
        elif address is None:
            _start_local(int(workers or usable_cores()))
            self._owns_ray = True
        else:
            _connect(address)
            self._owns_ray = True
        cpus = int(ray.cluster_resources().get("CPU", 1))
        self.workers = int(workers) if workers else max(1, cpus)
        self._warm_up(min(self.workers, max(1, cpus)))

    # -- single submissions (no retries; ``map`` is the fault-tolerant path) ------------------------
    def submit(self, fn: Callable[[Any], Any], task: Any) -> Future:
        ref = _remote_apply.remote(fn, task)
        fut = ref.future()
        fut.ray_ref = ref  # so that ``collect`` can stop an attempt past its timeout
        return fut

    # -- ``collect`` (base class): the same faults as ``map`` for submitted tasks -------------------
    def _is_fault(self, exc: BaseException) -> bool:
        if isinstance(exc, rex.RayTaskError):  # raised by the task: a fault only if it says so
            return is_worker_fault(getattr(exc, "cause", None))
        return isinstance(exc, _RETRYABLE)

    def _raise_task_error(self, exc: BaseException) -> None:
        cause = getattr(exc, "cause", None) if isinstance(exc, rex.RayTaskError) else None
        if isinstance(cause, BaseException):
            raise cause from exc
        raise exc

    def _abandon(self, futures) -> None:
        for fut in futures:
            ref = getattr(fut, "ray_ref", None)
            if ref is not None:
                ray.cancel(ref, force=True)  # kills the worker running it
        self.retries += len(futures)

    # -- fault-tolerant ordered map -----------------------------------------------------------------
    def map(self, fn: Callable[[Any], Any], tasks: Sequence[Any]) -> list[Any]:
        if not tasks:
            return []
        fn_ref = ray.put(fn)  # shared by every task and every retry
        task_refs = [ray.put(t) for t in tasks]  # each task crosses the wire once
        attempts = [0] * len(tasks)
        results: dict[int, Any] = {}
        running: dict[ray.ObjectRef, tuple[int, float]] = {}  # ref -> (task index, deadline)
        timeout = self.task_timeout_s or math.inf

        def launch(i: int) -> None:
            attempts[i] += 1
            running[_remote_apply.remote(fn_ref, task_refs[i])] = (i, time.monotonic() + timeout)

        def retry(i: int, why: str) -> None:
            if attempts[i] > self.max_retries:
                self._cancel(running)
                raise ExecutorError(
                    f"task {i} failed {attempts[i]} time(s), last: {why}; giving up "
                    f"(max_retries={self.max_retries})"
                )
            self.retries += 1
            self._warm_up(1)  # a replacement worker starts before the retry's clock does
            launch(i)

        for i in range(len(tasks)):
            launch(i)
        while running:
            wait_s = max(0.0, min(d for _, d in running.values()) - time.monotonic())
            ready, _ = ray.wait(list(running), num_returns=1, timeout=None if wait_s == math.inf else wait_s)
            for ref in ready:
                i, _ = running.pop(ref)
                try:
                    results[i] = ray.get(ref)
                except rex.RayTaskError as exc:  # raised inside the task (fn, or unpickling it): no retry
                    cause = exc.cause if isinstance(exc.cause, BaseException) else None
                    if is_worker_fault(cause):  # the worker's resource was lost (a simulator server)
                        retry(i, f"worker fault: {cause}")
                        continue
                    self._cancel(running)
                    if cause is None:
                        raise
                    raise cause from exc
                except _RETRYABLE as exc:
                    retry(i, type(exc).__name__)
            now = time.monotonic()
            for ref, (i, deadline) in list(running.items()):
                if deadline <= now and not ray.wait([ref], timeout=0)[0]:
                    del running[ref]
                    ray.cancel(ref, force=True)  # kills the worker process running it
                    retry(i, f"timed out after {timeout:g} s")
        return [results[i] for i in range(len(tasks))]

    def _warm_up(self, n: int) -> None:
        """Run ``n`` short no-op tasks so that ``n`` worker processes are up (start-up is untimed)."""
        refs = [_remote_pid.remote(0.05) for _ in range(n)]
        try:
            ray.get(refs, timeout=self.startup_timeout_s)
        except rex.GetTimeoutError:
            for ref in refs:
                ray.cancel(ref, force=True)
            raise ExecutorError(f"Ray workers did not start within {self.startup_timeout_s:g} s") from None

    @staticmethod
    def _cancel(running: dict) -> None:
        """Stop the other attempts of a map that is being abandoned (their workers live on)."""
        for ref in running:
            ray.cancel(ref)
        running.clear()

    def shutdown(self) -> None:
        if self._owns_ray and ray.is_initialized():
            ray.shutdown()  # laptop mode: stops the private Ray; cluster mode: disconnects
        self._owns_ray = False


__all__ = ["RayExecutor", "LOOPBACK"]
