"""The run directory: config, metrics, checkpoints, TensorBoard events; every write is atomic.

Layout::

    RUN/config.yaml              complete, validated, re-runnable config
    RUN/run.json                 the run's id (random, written once when the run is created)
    RUN/metrics.csv              one row per generation (same columns for every method)
    RUN/tb/                      TensorBoard events of the same metrics
    RUN/checkpoints/gen_NNNNNN.npz + .json    arrays (never pickle) + JSON metadata; the arrays name the
                                 run and generation (checkpoint/run_id, checkpoint/generation), the JSON
                                 holds their sha256 (arrays_sha256): a file from elsewhere is refused
    RUN/checkpoints/latest.json  name of the newest complete checkpoint (written last)
    RUN/trajectories/            Parquet shards (shaped method)
    RUN/mphi_data/               M_phi's training rows, one part per generation (shaped method)
    RUN/label_probe.json         the frame the label probe chose (shaped method, frame auto)
    RUN/pruned.json              written by ``shaped-es prune`` (``prune.py``) once it deleted what an exact
                                 resume reads (mphi_data*, trajectories): resume refuses the run
    RUN/figures/                 plots
    RUN/.lock                    pid of the process writing the run (train, resume, benchmark)
    RUN/error.log                full tracebacks of errors the command line reported in one line

Crash safety: every file is written to a ``.NAME.*.tmp`` file, fsynced and renamed, and a checkpoint is
its ``.npz`` then its ``.json``; a checkpoint is complete once both exist. A kill at any point leaves the
previous complete checkpoint in force. :meth:`RunStore.recover` (resume) deletes what a killed writer
left (the temporaries of the files the run writes, :data:`RUN_FILES`, in their own folders only; an
``.npz`` without its ``.json``), takes the newest complete checkpoint, whatever
``latest.json`` says (it only names the newest one for people and other tools, and is rewritten), and
drops the ``metrics.csv`` rows the checkpoint does not cover, a torn last row included (repeated rows,
which two writers at once leave, are reduced to the last of each generation; rows the checkpoint covers
that are missing are an error: nothing is changed).

A run directory is the run's own: ``train --out`` takes only a new or empty folder (or one a failed
start left), never a folder of other files or the empty path (:meth:`RunStore.check_new`).

One writer at a time: :meth:`RunStore.lock` takes an exclusive lock (``lock.py``: the run directory
itself ``flock``-ed, so deleting ``RUN/.lock`` does not let a second writer in, and ``RUN/.lock`` naming
the holder; a killed holder's lock is free again). Writes outside a held lock check that no other
process holds it.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import sys
import time
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from shaped_es.rundir import metrics_csv
from shaped_es.config import RunConfig, build_config, dump_config, read_yaml
from shaped_es.rundir.env_source import changed, fingerprint
from shaped_es.rundir.lock import HELD, LOCK_NAME, acquire, probe, release
from shaped_es.rundir.atomic import (  # noqa: F401 - StoreWarning, atomic_write_bytes: re-exported
    StoreError, StoreWarning, atomic_write_bytes, atomic_write_text, check_regular, open_append, read_regular)
from shaped_es.rundir.checkpoints import (  # noqa: F401 - all but CheckpointFiles: re-exported
    BIND_PREFIX, DIGEST_KEY, GEN_KEY, RUN_KEY, CheckpointFiles, arrays_digest, bind)
from shaped_es.rundir.recovery import _TMP_RES, RUN_FILES, Recovery  # noqa: F401 - RUN_FILES: re-exported

ERROR_LOG = "error.log"
_RUN_ID_RE = re.compile(r"[0-9a-f]{16,64}")
# what a start that failed before its config was written leaves: ``train --out`` may start there again
_START_LEFTOVERS = re.compile(rf"{re.escape(LOCK_NAME)}|{re.escape(ERROR_LOG)}|run\.json|{_TMP_RES['.'].pattern}")

# Fields added after runs were saved, whose default differs from what those runs did. A run's config.yaml
# lists every field, so one without such a field ran the old way: it is read (resumed, reported) as that.
SAVED_BEFORE = {("rollout", "test_policy"): "best",  # the tested policy before rollout.test_policy existed
                ("shaping", "mean_clone", "probe_candidate"): False,  # no generation-0 candidate before it
                ("shaping", "inverse_dynamics", "probe_chunk"): 0}  # the probe tried one-step targets only


class RunStore(CheckpointFiles, Recovery):
    """The run directory ``root``: its paths, lock, config, metrics and error log here; its checkpoints
    (:class:`~shaped_es.rundir.checkpoints.CheckpointFiles`) and what resume repairs
    (:class:`~shaped_es.rundir.recovery.Recovery`) in their own files."""

    def __init__(self, root: str | Path):
        self.root = Path(root)
        self._empty_path = isinstance(root, str) and not root.strip()  # Path("") is the working folder

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
    def run_json(self) -> Path:
        return self.root / "run.json"

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
        if self.holds_lock() or not self.root.is_dir():
            return
        probe(self.root)

    # -- config ------------------------------------------------------------------------------------
    def exists(self) -> bool:
        return self.config_path.is_file()

    def check_new(self) -> None:
        """``StoreError`` unless the run directory can be a new run's: absent, empty, or holding only what
        a start that failed left (a run directory is a folder the run owns: resume's clean-up deletes what
        it wrote there, so a folder of other files is refused, and so is an empty path, the working one)."""
        if self._empty_path:
            raise StoreError("--out is empty; name a new folder for the run (e.g. --out runs/first)")
        if self.root.exists() and not self.root.is_dir():
            raise StoreError(f"--out {self.root} exists and is not a directory")
        if self.exists():
            if not self._finished_any():  # a start that failed (a new user's env returned NaN at generation 0)
                raise StoreError(f"{self.root} holds a run that finished no generation (its start failed): "
                                 f"'shaped-es resume {self.root}' starts it again with its saved config, or "
                                 f"choose another --out (or delete that folder) to start with a new one")
            raise StoreError(
                f"{self.root} already holds a run; use 'shaped-es resume {self.root}' or another --out"
            )
        if not self.root.is_dir():
            return
        try:
            names = sorted(p.name for p in self.root.iterdir())
        except OSError as exc:
            raise StoreError(f"cannot list --out {self.root}: {exc.strerror or exc}") from None
        foreign = [n for n in names if not _START_LEFTOVERS.fullmatch(n)]
        if foreign:
            shown = ", ".join(foreign[:3]) + (", ..." if len(foreign) > 3 else "")
            raise StoreError(f"--out {self.root} is a folder that holds no run but other files ({shown}); a "
                             f"run directory is the run's own: name a new or empty folder")

    def _finished_any(self) -> bool:
        """A generation finished here: a metrics row or a checkpoint (unreadable ones count: not a fresh run)."""
        try:
            if self.metrics_path.is_file() and self.read_metrics():
                return True
            return self.ckpt_dir.is_dir() and any(self.ckpt_dir.iterdir())
        except (OSError, StoreError, ValueError):
            return True

    def create(self, cfg: RunConfig) -> None:
        self.check_new()
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"cannot create run directory {self.root}: {exc.strerror or exc}") from None
        self._check_writable()
        meta = {"run_id": uuid.uuid4().hex[:16]}
        source = fingerprint(cfg.env)  # a user's env module's source hash (env_source.py): an edit is then seen
        if source is not None:
            meta["env_source"] = source
        atomic_write_text(self.run_json, json.dumps(meta))  # before the config:
        atomic_write_text(self.config_path, dump_config(cfg))  # a run directory has its id from the start

    def run_id(self) -> str | None:
        """The run's id: random, written once by :meth:`create` (``RUN/run.json``), kept by resume (a
        shared ``shaping.trajectory_root`` keeps each run's shards under it); None for a run made before
        runs had one."""
        if not self.run_json.is_file():
            return None
        try:
            data = json.loads(read_regular(self.run_json).decode("utf-8"))
        except (OSError, ValueError):
            data = None
        rid = data.get("run_id") if isinstance(data, dict) else None
        if not isinstance(rid, str) or not _RUN_ID_RE.fullmatch(rid):
            raise StoreError(f"{self.run_json} holds no run id (a 16-64 digit hex 'run_id'); it names the "
                             f"run's trajectory shards, so restore it to resume")
        return rid

    def env_source(self) -> dict | None:
        """The env module's fingerprint :meth:`create` kept in ``run.json`` (None: none kept, or unreadable)."""
        try:
            data = json.loads(read_regular(self.run_json).decode("utf-8"))
        except (OSError, ValueError, StoreError):
            return None
        return data.get("env_source") if isinstance(data, dict) else None

    def env_changed(self, env_id: str, now: dict | None = None) -> str | None:
        """The env module's file name if it was edited since this run was made (``env_source.changed``; ``now``:
        the module's fingerprint if already taken, else taken here)."""
        return changed(self.env_source(), now or fingerprint(env_id))

    def save_config(self, cfg: RunConfig) -> None:
        """Make ``config.yaml`` say ``cfg`` (a no-op when it does): what ``resume`` (or a benchmark
        rerun) changes, its generations, executor or workers, written by the run loop once the
        restore held up, so a resume that fails leaves the config as it was."""
        if self.exists() and self.read_config() == cfg:
            return
        self._check_writable()
        atomic_write_text(self.config_path, dump_config(cfg))

    def read_config(self) -> RunConfig:
        check_regular(self.config_path)  # a folder or a named pipe: refused (a pipe would wait forever)
        if not self.exists():
            if not self.root.exists():
                raise StoreError(f"{self.root} is not a run directory: it does not exist")
            if not self.root.is_dir():
                raise StoreError(f"{self.root} is not a run directory (not a directory)")
            raise StoreError(f"{self.root} is not a run directory (no config.yaml)")
        data = read_yaml(self.config_path)
        if not data:  # every setting would be the default's, and no checkpoint would fit (not an older version)
            raise StoreError(f"{self.config_path} is empty (a run writes it whole, so something emptied it): restore "
                             f"the run's settings to it from a copy to use the run")
        for (*sections, key), before in SAVED_BEFORE.items():
            part = data
            for section in sections:
                part = part.get(section) if isinstance(part, dict) else None
            if isinstance(part, dict) and key not in part:
                part[key] = before
        return build_config(data)

    # -- metrics (metrics_csv.py) ------------------------------------------------------------------
    def read_metrics(self) -> list[dict[str, str]]:
        """Every complete row (a torn last row, left by a killed write, is not one)."""
        return metrics_csv.read_table(self.metrics_path)[1]

    def append_metrics(self, row: dict[str, Any]) -> None:
        """Append one row; the first row fixes the header (later rows may not add columns)."""
        self._check_writable()
        metrics_csv.append_row(self.metrics_path, row)

    def truncate_metrics(self, last_generation: int) -> None:
        """Drop rows after ``last_generation`` (rows a killed run wrote past its last checkpoint), a
        torn last row and repeated rows (the last of each generation stays); ``-1`` drops every row."""
        header, rows, _ = metrics_csv.rows_up_to(self.metrics_path, last_generation)
        self._check_writable()
        metrics_csv.write_rows(self.metrics_path, header, rows)

    # -- errors ------------------------------------------------------------------------------------
    def log_error(self, text: str) -> Path | None:
        """Append ``text`` (a traceback) to ``RUN/error.log``; None if the directory cannot take it."""
        if not self.root.is_dir():
            return None
        try:
            with open_append(self.error_log) as fh:
                fh.write(f"--- {time.strftime('%Y-%m-%d %H:%M:%S')} pid {os.getpid()}: "
                         f"{' '.join(sys.argv)}\n{text.rstrip()}\n")
        except (OSError, StoreError):
            return None
        return self.error_log
