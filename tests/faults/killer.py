"""``python killer.py POINT GEN ARGS...``: run ``shaped-es ARGS`` and SIGKILL this process at POINT of
the checkpoint of generation GEN (the checkpoint ``gen_GEN`` written after GEN generations):

- ``npz_tmp``: its ``.npz`` is written to a temporary file, not yet renamed
- ``npz_rename``: the ``.npz`` renamed, the ``.json`` not yet written
- ``json_rename``: the ``.json`` renamed, ``latest.json`` not yet
- ``latest``: ``latest.json`` renamed, older checkpoints not yet pruned
- ``metrics_append``: half of the metrics row of generation GEN written (a torn row)

Exit code -9 (SIGKILL) when the point was reached; otherwise the command's own.
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path

import shaped_es.rundir.store as store
from shaped_es.cli.commands import main

POINTS = ("npz_tmp", "npz_rename", "json_rename", "latest", "metrics_append")


def die() -> None:
    os.kill(os.getpid(), signal.SIGKILL)


def arm(point: str, gen: int) -> None:
    name = f"gen_{gen:06d}"
    real_replace = os.replace

    def replace(src, dst, *args, **kwargs):
        d = Path(dst)
        if point == "npz_tmp" and d.name == f"{name}.npz":
            die()
        real_replace(src, dst, *args, **kwargs)
        if (point == "npz_rename" and d.name == f"{name}.npz") or (
                point == "json_rename" and d.name == f"{name}.json") or (
                point == "latest" and d.name == "latest.json" and name in d.read_text()):
            die()

    os.replace = replace
    real_append = store.RunStore.append_metrics

    def append(self, row):
        if point == "metrics_append" and int(row["generation"]) == gen:
            real_append(self, row)
            lines = self.metrics_path.read_bytes().splitlines(keepends=True)
            torn = lines[-1][: len(lines[-1]) // 2]
            self.metrics_path.write_bytes(b"".join(lines[:-1]) + torn)
            die()
        real_append(self, row)

    store.RunStore.append_metrics = append


if __name__ == "__main__":
    point, gen = sys.argv[1], int(sys.argv[2])
    assert point in POINTS, point
    arm(point, gen)
    sys.exit(main(sys.argv[3:]))
