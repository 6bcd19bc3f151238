"""The rows behaviour cloning ships to local worker processes, in one shared-memory segment.

Written by hand because no library we use does this small job: the master gathers each generation's
minibatch rows (``(draws, P, B, obs)`` states and their labels, ~13 MB on CarNav-v0) straight into a
segment it keeps across generations, and each worker maps its members' slice of it instead of receiving
a pickled copy (which cost ~20 ms a generation: copy, pickle, pipe, unpickle). Only for workers on the
master's machine (the ``process`` executor); others get the arrays in the task.

The master owns the segment (``SharedRows``: created, grown and unlinked here); a worker opens a
:class:`RowsRef` and keeps the mapping until the master replaces the segment. If the master dies, the
resource tracker Python starts with it unlinks the segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from multiprocessing import shared_memory

import numpy as np

_ALIGN = 64  # bytes: each array starts on a cache line


@dataclass(frozen=True)
class RowsRef:
    """Picklable handle of arrays in a shared segment: ``layout`` = ``(key, byte offset, shape)``."""

    name: str
    layout: tuple[tuple[str, int, tuple[int, ...]], ...]

    def open(self) -> dict[str, np.ndarray]:
        """The float32 arrays, as views of the segment (mapped once per process)."""
        shm = _OPEN.get(self.name)
        if shm is None:
            for old in list(_OPEN.values()):  # the master replaced its segment: drop the old mapping
                old.close()
            _OPEN.clear()
            shm = _OPEN[self.name] = shared_memory.SharedMemory(name=self.name)
        return _views(shm, self.layout)


def _views(shm: shared_memory.SharedMemory, layout) -> dict[str, np.ndarray]:
    """The float32 arrays of ``layout`` (``(key, byte offset, shape)``) as views of ``shm``."""
    return {k: np.ndarray(shape, np.float32, buffer=shm.buf, offset=off) for k, off, shape in layout}


_OPEN: dict[str, shared_memory.SharedMemory] = {}  # this process's mapping of the master's segment


class SharedRows:
    """The master's segment: :meth:`arrays` lays out float32 arrays in it (growing it when needed)."""

    def __init__(self):
        self._shm: shared_memory.SharedMemory | None = None

    def arrays(self, shapes: dict[str, tuple[int, ...]]) -> tuple[dict[str, np.ndarray], RowsRef]:
        layout, off = [], 0
        for key, shape in shapes.items():
            layout.append((key, off, tuple(int(x) for x in shape)))
            off += -(-math.prod(shape) * 4 // _ALIGN) * _ALIGN
        if self._shm is None or self._shm.size < off:
            self.close()
            self._shm = shared_memory.SharedMemory(create=True, size=max(off + off // 4, _ALIGN))  # +25%
        return _views(self._shm, layout), RowsRef(self._shm.name, tuple(layout))

    def close(self) -> None:
        if self._shm is not None:
            self._shm.close()
            self._shm.unlink()
            self._shm = None
