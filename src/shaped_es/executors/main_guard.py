"""A script that starts worker processes must guard its top level with ``if __name__ == "__main__":``.

The process executor's workers are started with ``spawn``/``forkserver``: each one imports the script
that started the run again (as ``__mp_main__``), so a script that calls ``shaped_es.train(...)`` at its
top level, unguarded, starts the run again in every worker: a storm of "already holds a run" tracebacks,
dead workers, "giving up", and a half-made run directory. :func:`exit_if_unguarded` catches it in the
parent before anything is written or started: it finds the statement of the ``__main__`` script that is
running (the script's ``<module>`` frame on the stack), reads the script, and if that statement is not
inside an ``if __name__ == "__main__":`` block, prints one line naming the guard and exits with code 2.
Interactive sessions, ``python -c`` and notebooks (no script file) and calls that do not come from the
script's top level (a test runner, an installed command) pass. In a worker that re-imports such a script
anyway, :func:`refuse_in_worker` raises before the run is started again.
"""

from __future__ import annotations

import ast
import sys

GUARD = 'if __name__ == "__main__":'


def _main_frame(main):
    """The frame running ``main``'s top level, if it is on the stack."""
    f = sys._getframe(1)
    while f is not None:
        if f.f_code.co_name == "<module>" and f.f_globals is vars(main):
            return f
        f = f.f_back
    return None


def _is_guard(node: ast.stmt) -> bool:
    """``if __name__ == "__main__":`` (either side of the ``==``)."""
    if not isinstance(node, ast.If) or not isinstance(node.test, ast.Compare):
        return False
    t = node.test
    if len(t.ops) != 1 or not isinstance(t.ops[0], ast.Eq):
        return False
    sides = [t.left, t.comparators[0]]
    names = [s.id for s in sides if isinstance(s, ast.Name)]
    consts = [s.value for s in sides if isinstance(s, ast.Constant)]
    return names == ["__name__"] and consts == ["__main__"]


def unguarded_call() -> str | None:
    """``"path:line"`` of the top-level statement of the running ``__main__`` script that led here when it
    is not inside ``if __name__ == "__main__":`` (None otherwise, or when there is no script to read)."""
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if main is None or not path:
        return None
    frame = _main_frame(main)
    if frame is None:
        return None
    try:
        with open(path, encoding="utf-8") as fh:
            tree = ast.parse(fh.read(), path)
    except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
        return None
    line = frame.f_lineno
    for node in tree.body:
        if node.lineno <= line <= (node.end_lineno or node.lineno):
            return None if _is_guard(node) else f"{path}:{line}"
    return None


def message(where: str, written: bool = False) -> str:
    return (f"{where} starts worker processes from the script's top level: put the call under "
            f'{GUARD} (each worker imports the script again, which would start the run again; or use '
            f"executor='inline'); " + ("no worker was started" if written else "nothing was written"))


def exit_if_unguarded(written: bool = False) -> None:
    """Print one line and exit with code 2 when the running script calls us unguarded (see above);
    ``written``: the caller may have written something already (the line does not say nothing was)."""
    where = unguarded_call()
    if where is not None:
        print(f"shaped-es: error: {message(where, written)}", file=sys.stderr, flush=True)
        raise SystemExit(2)


def refuse_in_worker() -> None:
    """Raise when a worker process is importing the script that started it (``__mp_main__``) and that
    import is starting a run again: the parent's check missed an unguarded call."""
    f = sys._getframe(1)
    while f is not None:
        if f.f_code.co_name == "<module>" and f.f_globals.get("__name__") == "__mp_main__":
            raise RuntimeError(f"a worker process is importing {f.f_globals.get('__file__')} again and it "
                               f"starts a run: put the script's top level under {GUARD}")
        f = f.f_back
