"""Other libraries' warnings (Gymnasium's env checker, NumPy, ...) go to the run's ``error.log``, one entry
each, instead of two lines apiece on the terminal; the command line then says, in one line, how many
there were (``cli_errors.WarningRoute``). Worker processes write their own entries to the same file
(:func:`to_log`; the process executor's workers install it with the path the trainer gives them).

An entry is ``--- TIME pid PID: warning from ORIGIN`` and the warning's usual text.
"""

from __future__ import annotations

import os
import stat
import time
import warnings
from pathlib import Path

MARK = ": warning from "  # in an entry's header line
ENV = "SHAPED_ES_WARNING_LOG"  # the log's path, set by the command line for the workers it starts


def origin(filename: str) -> str:
    """The package a warning came from (``gymnasium`` for .../site-packages/gymnasium/...)."""
    parts = Path(filename).parts
    for i, part in enumerate(parts[:-1]):
        if part in ("site-packages", "dist-packages"):
            return parts[i + 1]
    return Path(filename).stem


def _open(log: Path, flags: int, mode: str):
    """``log`` opened without waiting (a named pipe in its place would block): ``OSError`` unless it is
    a regular file."""
    fd = os.open(log, flags | os.O_NONBLOCK, 0o644)
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise OSError(f"{log} is not a regular file")
    os.set_blocking(fd, True)
    return os.fdopen(fd, mode)


def append(log: Path, source: str, text: str) -> bool:
    """Append one entry to ``log`` if its directory exists; True if it was written."""
    if not log.parent.is_dir():
        return False
    try:
        with _open(log, os.O_WRONLY | os.O_APPEND | os.O_CREAT, "a") as fh:
            fh.write(f"--- {time.strftime('%Y-%m-%d %H:%M:%S')} pid {os.getpid()}{MARK}{source}\n"
                     f"{text.rstrip()}\n")
    except OSError:
        return False
    return True


def entries_since(log: Path, offset: int) -> list[str]:
    """The origins of the entries written to ``log`` past byte ``offset``, in order."""
    try:
        with _open(log, os.O_RDONLY, "rb") as fh:
            fh.seek(offset)
            text = fh.read().decode("utf-8", "replace")
    except OSError:
        return []
    return [line.split(MARK, 1)[1] for line in text.splitlines() if line.startswith("--- ") and MARK in line]


def to_log(log: str | None) -> None:
    """In a worker process: send every warning to ``log`` (None: leave warnings as they are)."""
    if not log:
        return

    def show(message, category, filename, lineno, file=None, line=None) -> None:
        append(Path(log), origin(filename), warnings.formatwarning(message, category, filename, lineno, line))

    warnings.showwarning = show
