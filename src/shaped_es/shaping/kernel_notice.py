"""One line before the shaping kernels compile (``shaping/kernels.py``: Numba, cached on disk).

The first run of a method that uses them after an install (or after an edit of ``kernels.py``, on another
CPU or Numba) compiles them, with nothing else to show: 8 s measured on an idle 2-core machine, 19-28 s
in docs/shaped-results.md; every later run loads them from Numba's cache in well under a second. The
line comes only when Numba's cache holds no compile of them (``kernels.cached()`` is False), before the
run starts the work that compiles them (the shaped method's label probe, then its guide's warm-up); never
when the cache is warm, nor when it cannot tell.
"""

from __future__ import annotations

import sys

NOTICE = "compiling the shaping kernels (the first run after an install: up to ~30 s; cached afterwards)"


def compile_ahead() -> bool:
    """Whether the next use of the shaping kernels in this process compiles them."""
    from shaped_es.shaping import kernels

    return kernels.ENABLED and kernels.cached() is False


def say_if_compiling(label: str, stream=None) -> bool:
    """Print ``[label] compiling the shaping kernels ...`` to stderr if :func:`compile_ahead`; returns
    whether it printed."""
    if not compile_ahead():
        return False
    print(f"[{label}] {NOTICE}", file=stream or sys.stderr, flush=True)
    return True
