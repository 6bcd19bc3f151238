"""The run directory's two primitives: its one error type and the atomic file write every write uses
(temporary ``.NAME.*.tmp``, fsync, rename)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path


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
