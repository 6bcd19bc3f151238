"""M_phi's aggregated data set on disk, saved once: the rows each generation added, one file each.

``RUN/mphi_data/added_{g:06d}.npz`` holds generation ``g``'s inputs ``x`` ``(rows, obs + d)`` and targets
``y`` ``(rows, act)``. A checkpoint names the parts (generation, rows) whose concatenation, cut to the
data set's FIFO size, rebuilds the data set exactly, instead of copying the whole data set (18 MB for
CarNav-v0) into every checkpoint. Arrays only (``allow_pickle=False``); writes are atomic.
"""

from __future__ import annotations

import io
import re
import time
import zipfile
from pathlib import Path

import numpy as np

from shaped_es.rundir.store import atomic_write_bytes

_PART_RE = re.compile(r"added_(\d{6,})\.npz")


class DamagedPart(ValueError):
    """A data part on disk that cannot be read as written (not one that is missing, or another setup's)."""


class DataParts:
    """The part files under ``root`` and the list ``kept`` of (generation, rows) a checkpoint names."""

    def __init__(self, root: Path):
        self.root = Path(root)
        self.kept: list[tuple[int, int]] = []

    def path(self, generation: int) -> Path:
        return self.root / f"added_{generation:06d}.npz"

    def add(self, generation: int, rows: int) -> None:
        self.kept.append((generation, rows))

    def write(self, generation: int, x: np.ndarray, y: np.ndarray) -> float:
        """Write one generation's rows (atomically); returns the seconds it took."""
        t0 = time.perf_counter()
        buf = io.BytesIO()
        np.savez(buf, x=x, y=y)
        atomic_write_bytes(self.path(generation), buf.getvalue())
        return time.perf_counter() - t0

    def trim(self, dataset_size: int) -> None:
        """Keep in :attr:`kept` only the newest parts that hold a data set of ``dataset_size`` rows."""
        need, kept = dataset_size, []
        for g, rows in reversed(self.kept):
            if need <= 0:
                break
            kept.insert(0, (g, rows))
            need -= rows
        self.kept = kept

    def oldest(self, default: int) -> int:
        return self.kept[0][0] if self.kept else default

    def delete_before(self, generation: int) -> None:
        """Remove the part files of generations below ``generation``."""
        if not self.root.is_dir():
            return
        for f in self.root.iterdir():
            m = _PART_RE.fullmatch(f.name)
            if m and int(m.group(1)) < generation:
                f.unlink(missing_ok=True)

    def read(self, parts: np.ndarray, size: int, in_dim: int, act_dim: int) -> tuple[np.ndarray, np.ndarray]:
        """The data set (its last ``size`` rows) rebuilt from ``parts`` ``(k, 2)``; ``ValueError`` (one
        line) if a part is missing, unreadable or not the size the checkpoint says. Sets :attr:`kept`."""
        xs, ys = [], []
        for g, rows in parts.reshape(-1, 2):
            path = self.path(int(g))
            try:
                with np.load(path, allow_pickle=False) as z:
                    x, y = z["x"], z["y"]
            except FileNotFoundError:
                raise ValueError(f"M_phi data part {path} is missing") from None
            except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
                raise DamagedPart(f"M_phi data part {path} is unreadable ({type(exc).__name__})") from None
            if x.shape[:1] != (int(rows),) or y.shape[:1] != (int(rows),):
                raise DamagedPart(f"M_phi data part {path} holds {x.shape[:1]} rows, the checkpoint says {rows}")
            if x.shape != (int(rows), in_dim) or y.shape != (int(rows), act_dim) or \
                    not (np.isfinite(x).all() and np.isfinite(y).all()):
                raise ValueError(f"M_phi data part {path} is not this run's (shapes {x.shape}, {y.shape} or "
                                 f"non-finite values)")
            xs.append(x)
            ys.append(y)
        x = np.concatenate(xs) if xs else np.zeros((0, in_dim), np.float32)
        y = np.concatenate(ys) if ys else np.zeros((0, act_dim), np.float32)
        if x.shape[0] < size:
            raise ValueError(f"M_phi data parts hold {x.shape[0]} rows, the checkpoint needs {size}")
        self.kept = [(int(g), int(r)) for g, r in parts.reshape(-1, 2)]
        return x[x.shape[0] - size :], y[y.shape[0] - size :]
