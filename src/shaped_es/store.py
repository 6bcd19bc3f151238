"""The run directory: config, metrics, checkpoints, TensorBoard events; every write is atomic.

Layout::

    RUN/config.yaml              complete, validated, re-runnable config
    RUN/metrics.csv              one row per generation (same columns for every method)
    RUN/tb/                      TensorBoard events of the same metrics
    RUN/checkpoints/gen_NNNNNN.npz + .json    arrays (never pickle) + JSON metadata
    RUN/checkpoints/latest.json  name of the newest complete checkpoint (written last)
    RUN/trajectories/            Parquet shards (shaped method)
    RUN/figures/                 plots

A checkpoint is complete once ``latest.json`` names it; a crash mid-write leaves the previous one in force.
"""

from __future__ import annotations

import csv
import io
import json
import math
import os
import tempfile
import zipfile
from pathlib import Path
from typing import Any

import numpy as np

from shaped_es.config import RunConfig, build_config, dump_config, read_yaml


class StoreError(RuntimeError):
    """The run directory is missing, foreign, or holds a malformed file (message: one line)."""


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


class RunStore:
    def __init__(self, root: str | Path):
        self.root = Path(root)

    # -- paths -------------------------------------------------------------------------------------
    @property
    def config_path(self) -> Path:
        return self.root / "config.yaml"

    @property
    def metrics_path(self) -> Path:
        return self.root / "metrics.csv"

    @property
    def ckpt_dir(self) -> Path:
        return self.root / "checkpoints"

    @property
    def trajectories_dir(self) -> Path:
        return self.root / "trajectories"

    @property
    def figures_dir(self) -> Path:
        return self.root / "figures"

    # -- config ------------------------------------------------------------------------------------
    def exists(self) -> bool:
        return self.config_path.is_file()

    def create(self, cfg: RunConfig) -> None:
        if self.exists():
            raise StoreError(
                f"{self.root} already holds a run; use 'shaped-es resume {self.root}' or another --out"
            )
        if self.root.exists() and not self.root.is_dir():
            raise StoreError(f"--out {self.root} exists and is not a directory")
        self.root.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.config_path, dump_config(cfg))

    def read_config(self) -> RunConfig:
        if not self.exists():
            raise StoreError(f"{self.root} is not a run directory (no config.yaml)")
        return build_config(read_yaml(self.config_path))

    # -- metrics -----------------------------------------------------------------------------------
    def read_metrics(self) -> list[dict[str, str]]:
        if not self.metrics_path.is_file():
            return []
        with self.metrics_path.open(newline="") as fh:
            return list(csv.DictReader(fh))

    def append_metrics(self, row: dict[str, Any]) -> None:
        """Append one row; the first row fixes the header (later rows may not add columns)."""
        new = not self.metrics_path.is_file() or self.metrics_path.stat().st_size == 0
        if new:
            fields = list(row)
        else:
            with self.metrics_path.open(newline="") as fh:
                fields = next(csv.reader(fh))
            extra = set(row) - set(fields)
            if extra:
                raise StoreError(f"metrics row has columns not in {self.metrics_path}: {sorted(extra)}")
        with self.metrics_path.open("a", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=fields)
            if new:
                w.writeheader()
            w.writerow({k: _fmt(row.get(k)) for k in fields})
            fh.flush()
            os.fsync(fh.fileno())

    def truncate_metrics(self, last_generation: int) -> None:
        """Drop rows after ``last_generation`` (rows a killed run wrote past its last checkpoint)."""
        rows = self.read_metrics()
        if not rows:
            return
        fields = list(rows[0])
        keep = [r for r in rows if int(r["generation"]) <= last_generation]
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
        w.writeheader()
        w.writerows(keep)
        atomic_write_text(self.metrics_path, buf.getvalue())

    # -- checkpoints -------------------------------------------------------------------------------
    def save_checkpoint(self, generation: int, arrays: dict[str, np.ndarray], meta: dict, keep: int) -> Path:
        name = f"gen_{generation:06d}"
        buf = io.BytesIO()
        np.savez(buf, **{k: np.asarray(v) for k, v in arrays.items()})
        atomic_write_bytes(self.ckpt_dir / f"{name}.npz", buf.getvalue())
        atomic_write_text(self.ckpt_dir / f"{name}.json", json.dumps({**meta, "generation": generation}))
        atomic_write_text(self.ckpt_dir / "latest.json", json.dumps({"name": name}))
        olds = sorted(self.ckpt_dir.glob("gen_*.npz"))[:-keep]
        for old in olds:
            old.unlink(missing_ok=True)
            old.with_suffix(".json").unlink(missing_ok=True)
        return self.ckpt_dir / f"{name}.npz"

    def load_checkpoint(self) -> tuple[dict[str, np.ndarray], dict] | None:
        """The newest complete checkpoint as (arrays, meta), or None if the run has none yet."""
        latest = self.ckpt_dir / "latest.json"
        if not latest.is_file():
            return None
        try:
            name = json.loads(latest.read_text())["name"]
            meta = json.loads((self.ckpt_dir / f"{name}.json").read_text())
            with np.load(self.ckpt_dir / f"{name}.npz", allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, KeyError, ValueError, zipfile.BadZipFile, json.JSONDecodeError) as exc:
            raise StoreError(f"checkpoint in {self.ckpt_dir} is unreadable: {type(exc).__name__}") from None
        return arrays, meta


def _fmt(v: Any) -> Any:
    if v is None:
        return ""
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return "" if math.isnan(f) else repr(f)
    if isinstance(v, np.integer):
        return int(v)
    return v
