"""The run directory: config, metrics, checkpoints, TensorBoard events; every write is atomic.

Layout::

    RUN/config.yaml              complete, validated, re-runnable config
    RUN/metrics.csv              one row per generation (same columns for every method)
    RUN/tb/                      TensorBoard events of the same metrics
    RUN/checkpoints/gen_NNNNNN.npz + .json    arrays (never pickle) + JSON metadata
    RUN/checkpoints/latest.json  name of the newest complete checkpoint (written last)
    RUN/trajectories/            Parquet shards (shaped method)
    RUN/figures/                 plots
    RUN/.lock                    pid of the process writing the run (train, resume, benchmark)
    RUN/error.log                full tracebacks of errors the command line reported in one line

Crash safety: every file is written to a ``.NAME.*.tmp`` file, fsynced and renamed, and a checkpoint is
its ``.npz`` then its ``.json``; a checkpoint is complete once both exist. A kill at any point leaves the
previous complete checkpoint in force. :meth:`RunStore.recover` (resume) deletes what a killed writer
left (``.tmp`` files, an ``.npz`` without its ``.json``), takes the newest complete checkpoint, whatever
``latest.json`` says (it only names the newest one for people and other tools, and is rewritten), and
drops the ``metrics.csv`` rows the checkpoint does not cover, a torn last row included.

One writer at a time: :meth:`RunStore.lock` takes an exclusive lock (``RUN/.lock`` holding the pid,
``flock``-ed, so a killed holder's lock is free again; without ``flock`` a lock of a dead pid on this
host is taken over). Writes outside a held lock check that no other process holds it.
"""

from __future__ import annotations

import contextlib
import csv
import io
import json
import math
import os
import re
import sys
import time
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from shaped_es.config import RunConfig, build_config, dump_config, read_yaml
from shaped_es.run_lock import HELD, LOCK_NAME, acquire, release
from shaped_es.store_io import StoreError, atomic_write_bytes, atomic_write_text

ERROR_LOG = "error.log"
_CKPT_RE = re.compile(r"gen_(\d{6,})")
_NON_FLOAT = ("", "True", "False")  # empty: no value (None or NaN); booleans as csv writes them
_TMP_RE = re.compile(r"\..+\.tmp")  # atomic_write_bytes' (and the trajectory store's) temporaries


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

    @property
    def lock_path(self) -> Path:
        return self.root / LOCK_NAME

    @property
    def error_log(self) -> Path:
        return self.root / ERROR_LOG

    # -- lock --------------------------------------------------------------------------------------
    def _lock_key(self) -> str:
        return os.path.realpath(self.lock_path)

    def holds_lock(self) -> bool:
        return self._lock_key() in HELD

    @contextlib.contextmanager
    def lock(self) -> Iterator[None]:
        """Hold the run's exclusive lock (re-entrant within this process); ``StoreError`` (one line
        naming the holder) if another live process holds it. Creates the run directory if needed."""
        key = self._lock_key()
        held = HELD.get(key)
        if held is None:
            if self.root.exists() and not self.root.is_dir():
                raise StoreError(f"{self.root} exists and is not a directory")
            try:
                self.root.mkdir(parents=True, exist_ok=True)
            except OSError as exc:
                raise StoreError(f"cannot create run directory {self.root}: {exc.strerror or exc}") from None
            held = HELD[key] = acquire(self.root)
        held.count += 1
        try:
            yield
        finally:
            held.count -= 1
            if held.count == 0:
                HELD.pop(key, None)
                release(held)

    def _check_writable(self) -> None:
        """A write outside :meth:`lock`: refused while another live process holds the lock."""
        if self.holds_lock() or not self.lock_path.exists():
            return
        with self.lock():
            pass

    # -- config ------------------------------------------------------------------------------------
    def exists(self) -> bool:
        return self.config_path.is_file()

    def create(self, cfg: RunConfig) -> None:
        if self.root.exists() and not self.root.is_dir():
            raise StoreError(f"--out {self.root} exists and is not a directory")
        if self.exists():
            raise StoreError(
                f"{self.root} already holds a run; use 'shaped-es resume {self.root}' or another --out"
            )
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"cannot create run directory {self.root}: {exc.strerror or exc}") from None
        self._check_writable()
        atomic_write_text(self.config_path, dump_config(cfg))

    def read_config(self) -> RunConfig:
        if not self.exists():
            if not self.root.exists():
                raise StoreError(f"{self.root} is not a run directory: it does not exist")
            if not self.root.is_dir():
                raise StoreError(f"{self.root} is not a run directory (not a directory)")
            raise StoreError(f"{self.root} is not a run directory (no config.yaml)")
        return build_config(read_yaml(self.config_path))

    # -- metrics -----------------------------------------------------------------------------------
    def _metrics_table(self) -> tuple[list[str], list[dict[str, str]]]:
        """(header, complete rows) of metrics.csv; a torn last line (no newline: a write cut short) is
        left out; anything else malformed is a ``StoreError``."""
        path = self.metrics_path
        if not path.exists():
            return [], []
        try:
            text = path.read_bytes().decode("utf-8")
        except UnicodeDecodeError:
            raise StoreError(f"{path} is not a CSV text file (binary content)") from None
        except OSError as exc:
            raise StoreError(f"cannot read {path}: {exc.strerror or exc}") from None
        if "\x00" in text:
            raise StoreError(f"{path} is not a CSV text file (binary content)")
        lines = text.splitlines(keepends=True)
        if lines and not lines[-1].endswith(("\n", "\r")):
            lines = lines[:-1]  # torn last row
        if not lines:
            return [], []
        try:
            table = list(csv.reader(lines))
        except csv.Error as exc:
            raise StoreError(f"{path} is not valid CSV: {exc}") from None
        header, body = table[0], table[1:]
        if not header or header[0] != "generation" or len(set(header)) != len(header):
            raise StoreError(f"{path} has no valid header (its first column must be 'generation')")
        rows, last = [], -1
        for i, cells in enumerate(body, start=2):
            if not cells:
                continue
            if len(cells) != len(header):
                raise StoreError(f"{path} line {i} has {len(cells)} fields, the header has {len(header)}")
            try:
                g = int(cells[0])
                for c in cells[1:]:
                    if c not in _NON_FLOAT:
                        float(c)
            except ValueError:
                raise StoreError(f"{path} line {i} holds a non-numeric value") from None
            if g <= last:
                raise StoreError(f"{path} line {i}: generation {g} does not follow generation {last}")
            last = g
            rows.append(dict(zip(header, cells)))
        return header, rows

    def read_metrics(self) -> list[dict[str, str]]:
        """Every complete row (a torn last row, left by a killed write, is not one)."""
        return self._metrics_table()[1]

    def append_metrics(self, row: dict[str, Any]) -> None:
        """Append one row; the first row fixes the header (later rows may not add columns)."""
        self._check_writable()
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
        """Drop rows after ``last_generation`` (rows a killed run wrote past its last checkpoint) and a
        torn last row; ``-1`` drops every row."""
        if not self.metrics_path.exists():
            return
        header, rows = self._metrics_table()
        keep = [r for r in rows if int(r["generation"]) <= last_generation]
        buf = io.StringIO()
        if header:
            w = csv.DictWriter(buf, fieldnames=header)  # "\r\n", as append_metrics writes
            w.writeheader()
            w.writerows(keep)
        if buf.getvalue().encode() == self.metrics_path.read_bytes():
            return
        self._check_writable()
        atomic_write_text(self.metrics_path, buf.getvalue())

    # -- checkpoints -------------------------------------------------------------------------------
    def _check_ckpt_dir(self) -> bool:
        """True if the checkpoint directory exists; ``StoreError`` if something else is in its place."""
        if not self.ckpt_dir.exists():
            return False
        if not self.ckpt_dir.is_dir():
            raise StoreError(f"{self.ckpt_dir} is not a directory; move it away to resume")
        return True

    def save_checkpoint(self, generation: int, arrays: dict[str, np.ndarray], meta: dict, keep: int) -> Path:
        self._check_writable()
        if self.ckpt_dir.exists() and not self.ckpt_dir.is_dir():
            raise StoreError(f"{self.ckpt_dir} is not a directory; move it away to resume")
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

    def checkpoints(self) -> list[int]:
        """Generations of the complete checkpoints on disk (``.npz`` and ``.json`` both present), ascending."""
        if not self._check_ckpt_dir():
            return []
        names = {p.name for p in self.ckpt_dir.iterdir()}
        gens = []
        for n in names:
            m = _CKPT_RE.fullmatch(n[:-4]) if n.endswith(".npz") else None
            if m and f"{n[:-4]}.json" in names:
                gens.append(int(m.group(1)))
        return sorted(gens)

    def _latest_named(self) -> int | None:
        """The generation ``latest.json`` names (None if absent or unreadable); ``StoreError`` if it names
        anything but a checkpoint of this directory (``../../x``)."""
        latest = self.ckpt_dir / "latest.json"
        try:
            data = json.loads(latest.read_bytes().decode("utf-8"))
        except (OSError, ValueError):  # absent, binary or not JSON: it is advisory, the scan decides
            return None
        name = data.get("name") if isinstance(data, dict) else None
        if name is None:
            return None
        m = _CKPT_RE.fullmatch(name) if isinstance(name, str) else None
        if m is None:
            raise StoreError(f"{latest} names {name!r}, which is not a checkpoint of this run (gen_NNNNNN); "
                             f"delete {latest.name} to resume from the newest checkpoint found")
        return int(m.group(1))

    def newest_generation(self) -> int:
        """Generations covered by the newest complete checkpoint (0 without one); reads no arrays."""
        gens = self.checkpoints()
        return gens[-1] if gens else 0

    def checkpoint_meta(self) -> dict | None:
        """The newest complete checkpoint's metadata, None without one."""
        loaded = self.load_checkpoint()
        return None if loaded is None else loaded[1]

    def require_checkpoint(self) -> tuple[dict[str, np.ndarray], dict]:
        """:meth:`load_checkpoint`, with one clear ``StoreError`` when the run has none yet."""
        loaded = self.load_checkpoint()
        if loaded is None:
            raise StoreError(f"{self.root} has no checkpoint yet")
        return loaded

    def load_checkpoint(self) -> tuple[dict[str, np.ndarray], dict] | None:
        """The newest complete checkpoint as (arrays, meta), or None if the run has none yet.

        Found by scanning ``checkpoints/`` (``latest.json`` is advisory: it may lag a kill by one
        checkpoint, or be missing); one that is unreadable is an error naming it, never silently
        skipped."""
        gens = self.checkpoints()
        named = self._latest_named() if self.ckpt_dir.is_dir() else None
        if named is not None and (not gens or named > gens[-1]):
            have = f"the newest found is gen_{gens[-1]:06d}" if gens else "none is found"
            raise StoreError(f"{self.ckpt_dir}/latest.json names gen_{named:06d}, which is missing "
                             f"({have}); delete latest.json to resume from what is there")
        if not gens:
            return None
        g = gens[-1]
        name = f"gen_{g:06d}"
        older = f"; delete {name}.npz and {name}.json to resume from gen_{gens[-2]:06d}" if len(gens) > 1 else ""
        try:
            meta = json.loads((self.ckpt_dir / f"{name}.json").read_bytes().decode("utf-8"))
            with np.load(self.ckpt_dir / f"{name}.npz", allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            why = type(exc).__name__
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} is unreadable ({why}){older}") from None
        if not isinstance(meta, dict) or meta.get("generation") != g or isinstance(meta.get("generation"), bool):
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} is unreadable (its .json is not this "
                             f"checkpoint's metadata){older}")
        return arrays, meta

    # -- resume ------------------------------------------------------------------------------------
    def clean_temporaries(self) -> list[Path]:
        """Delete ``.*.tmp`` files a killed writer left in the run directory (and its sub-directories)
        and checkpoint files without their pair; returns what was deleted. Only for the lock holder."""
        removed = []
        for dirpath, dirnames, filenames in os.walk(self.root):
            dirnames[:] = [d for d in dirnames if d not in ("tb", "figures")]
            for f in filenames:
                if _TMP_RE.fullmatch(f):
                    p = Path(dirpath) / f
                    p.unlink(missing_ok=True)
                    removed.append(p)
        if self._check_ckpt_dir():
            names = {p.name for p in self.ckpt_dir.iterdir()}
            for n in names:
                stem, ext = os.path.splitext(n)
                other = {".npz": ".json", ".json": ".npz"}.get(ext)
                if other and _CKPT_RE.fullmatch(stem) and stem + other not in names:
                    p = self.ckpt_dir / n  # half a checkpoint: its pair was never written, or pruned
                    p.unlink(missing_ok=True)
                    removed.append(p)
        return removed

    def recover(self, loaded: Any = ...) -> tuple[dict[str, np.ndarray], dict] | None:
        """Make the run directory consistent before a writer continues it (call with the lock held):
        delete what a killed writer left, load the newest complete checkpoint (``load_checkpoint``, or
        take ``loaded``, what it returned), point ``latest.json`` at it and drop the metrics rows it does
        not cover (every row without a checkpoint; the rows still waiting for test episodes when it was
        written are written again)."""
        self._check_writable()
        if loaded is ...:
            loaded = self.load_checkpoint()  # validates before anything is changed
        self.clean_temporaries()
        if loaded is None:
            self.truncate_metrics(-1)
            if self.ckpt_dir.is_dir():
                (self.ckpt_dir / "latest.json").unlink(missing_ok=True)
            return None
        _, meta = loaded
        g = int(meta["generation"])
        if self._latest_named() != g:
            atomic_write_text(self.ckpt_dir / "latest.json", json.dumps({"name": f"gen_{g:06d}"}))
        waiting = [r.get("generation") for r in meta.get("waiting_rows") or [] if isinstance(r, dict)]
        waiting = [int(x) for x in waiting if isinstance(x, int)]
        self.truncate_metrics((min(waiting) if waiting else g) - 1)
        return loaded

    # -- errors ------------------------------------------------------------------------------------
    def log_error(self, text: str) -> Path | None:
        """Append ``text`` (a traceback) to ``RUN/error.log``; None if the directory cannot take it."""
        if not self.root.is_dir():
            return None
        try:
            with self.error_log.open("a") as fh:
                fh.write(f"--- {time.strftime('%Y-%m-%d %H:%M:%S')} pid {os.getpid()}: "
                         f"{' '.join(sys.argv)}\n{text.rstrip()}\n")
        except OSError:
            return None
        return self.error_log


def _fmt(v: Any) -> Any:
    if v is None:
        return ""
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return "" if math.isnan(f) else repr(f)
    if isinstance(v, np.integer):
        return int(v)
    return v
