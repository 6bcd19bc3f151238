"""The run directory's primitives: its one error type, the atomic file write every write uses
(temporary ``.NAME.*.tmp``, fsync, rename), and reads and appends of regular files only (a named pipe in
the run directory would make them wait forever: it is refused in one line)."""

from __future__ import annotations

import errno
import os
import re
import stat
import tempfile
import time
from collections.abc import Iterable
from pathlib import Path

STALE_TMP_S = 600.0  # a temporary older than this is a killed writer's (a write takes well under a second)


class StoreError(RuntimeError):
    """The run directory is missing, foreign, locked, or holds a malformed file (message: one line)."""


class StoreWarning(UserWarning):
    """Something ``resume`` repaired in the run directory (printed as one line)."""


def atomic_write_bytes(path: Path, data: bytes) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def atomic_write_text(path: Path, text: str) -> None:
    atomic_write_bytes(path, text.encode())


def clean_stale_temporaries(folder: Path, names: Iterable[str], older_than_s: float = STALE_TMP_S) -> list[Path]:
    """Delete the temporaries :func:`atomic_write_bytes` made for ``names`` in ``folder`` (``.NAME.RANDOM.tmp``:
    regular files only, no symlink, no sub-folder) that were last written over ``older_than_s`` ago, so a
    killed writer's, not one another process is still writing (folders without a lock: a benchmark's, a
    suite's); returns what was deleted."""
    pattern = re.compile(rf"\.(?:{'|'.join(re.escape(n) for n in names)})\.[A-Za-z0-9_]+\.tmp")
    now, removed = time.time(), []
    for p in entries(folder):
        try:
            st = p.lstat()
        except OSError:
            continue
        if pattern.fullmatch(p.name) and stat.S_ISREG(st.st_mode) and now - st.st_mtime > older_than_s:
            p.unlink(missing_ok=True)
            removed.append(p)
    return removed


def _kind(mode: int) -> str:
    return ("a named pipe" if stat.S_ISFIFO(mode) else "a folder" if stat.S_ISDIR(mode) else
            "a socket" if stat.S_ISSOCK(mode) else "a device" if stat.S_ISCHR(mode) or stat.S_ISBLK(mode)
            else "not a regular file")


def not_regular(path: Path, mode: int) -> StoreError:
    return StoreError(f"{path} is {_kind(mode)}, not a regular file (a run reads and writes regular files "
                      f"only); move it away and restore the file")


def check_regular(path: Path) -> None:
    """``StoreError`` if ``path`` exists and is not a regular file (symlinks followed)."""
    try:
        mode = os.stat(path).st_mode
    except OSError:
        return
    if not stat.S_ISREG(mode):
        raise not_regular(path, mode)


def read_regular(path: Path) -> bytes:
    """The bytes of ``path``, a regular file: opened without blocking, so a named pipe (or a folder,
    a device) is ``StoreError`` at once; ``OSError`` as ``open`` raises it (absent, unreadable)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    with os.fdopen(fd, "rb") as fh:
        mode = os.fstat(fd).st_mode
        if not stat.S_ISREG(mode):
            raise not_regular(path, mode)
        return fh.read()


def open_append(path: Path, newline: str | None = None):
    """``path`` opened to append text (created if absent), a regular file only (``StoreError``)."""
    try:
        fd = os.open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NONBLOCK, 0o644)
    except OSError as exc:
        if exc.errno == errno.ENXIO:  # a named pipe nobody reads
            raise not_regular(path, stat.S_IFIFO) from None
        raise
    mode = os.fstat(fd).st_mode
    if not stat.S_ISREG(mode):
        os.close(fd)
        raise not_regular(path, mode)
    os.set_blocking(fd, True)
    return os.fdopen(fd, "a", newline=newline)


def real_dir(p: Path) -> bool:
    """A directory that is no symlink (a run directory's own folders; a link is never followed)."""
    return p.is_dir() and not p.is_symlink()


def entries(d: Path) -> list[Path]:
    """``d``'s entries, sorted; ``[]`` where it cannot be listed."""
    try:
        return sorted(d.iterdir())
    except OSError:
        return []
