"""Independent kernel calls of the shaped guide on threads: the run's clones of the mean and of each rival
(``mechanisms/candidate.py``). (The label probe's one fit of every simulated clone, split into a chunk per thread,
was measured no faster: 7.6-8.4 s against 6.5-7.9 s on a 200-d body; its kernel's BLAS products use the cores.)

Their compiled kernels (``shaping/kernels.py``, ``nogil``) release the GIL, and the run's workers wait for
them, so on a machine with several cores they run side by side; each call is the same computation as alone,
so the results do not depend on the threads (tested). Written by hand: one shared pool, so no generation pays
for starting threads.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

from shaped_es.executors.base import usable_cores

MAX_THREADS = 4
_POOL: ThreadPoolExecutor | None = None  # made at the first call with two or more calls and cores


def threads() -> int:
    """How many of the calls run at once: one per core this process may use (``usable_cores``), at most 4."""
    return min(MAX_THREADS, usable_cores())


def concurrently(calls: list) -> list:
    """Each of ``calls`` (no arguments) run, results in order: on up to :func:`threads` threads when there are
    several calls and cores, else here, one after another."""
    global _POOL
    if len(calls) < 2 or threads() < 2:
        return [c() for c in calls]
    if _POOL is None:
        _POOL = ThreadPoolExecutor(max_workers=threads(), thread_name_prefix="shaped-clone")
    return list(_POOL.map(lambda c: c(), calls))
