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
import hashlib
import io
import json
import os
import re
import sys
import time
import uuid
import warnings
import zipfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from shaped_es.rundir import metrics_csv
from shaped_es.config import RunConfig, build_config, dump_config, read_yaml
from shaped_es.rundir.lock import HELD, LOCK_NAME, acquire, probe, release
from shaped_es.rundir.atomic import (StoreError, StoreWarning, atomic_write_bytes, atomic_write_text, check_regular,
                                     open_append, read_regular)

ERROR_LOG = "error.log"
BIND_PREFIX = "checkpoint/"  # a checkpoint's arrays name their run and generation (bind())
RUN_KEY, GEN_KEY = BIND_PREFIX + "run_id", BIND_PREFIX + "generation"
DIGEST_KEY = "arrays_sha256"  # ... and its .json holds their digest (arrays_digest())
_CKPT_RE = re.compile(r"gen_(\d{6,})")
_RUN_ID_RE = re.compile(r"[0-9a-f]{16,64}")
# What the run writes, folder by folder (relative to the run directory; ``*`` a ``gen_NNNNNN`` folder):
# clean-up deletes only the temporaries of these names (``.NAME.RANDOM.tmp``: atomic_write_bytes' and the
# trajectory store's), never walking any other folder, so a run directory holds nothing else of value to it
RUN_FILES = {
    ".": r"config\.yaml|run\.json|metrics\.csv|wandb_id|label_probe\.json",
    "checkpoints": r"gen_\d{6,}\.(?:npz|json)|latest\.json",
    "mphi_data": r"added_\d{6,}\.npz",
    "trajectories/*": r"members_\d{4,}-\d{4,}\.parquet",
}
_TMP_RES = {d: re.compile(rf"\.(?:{names})\.[A-Za-z0-9_]+\.tmp") for d, names in RUN_FILES.items()}
# what a start that failed before its config was written leaves: ``train --out`` may start there again
_START_LEFTOVERS = re.compile(rf"{re.escape(LOCK_NAME)}|{re.escape(ERROR_LOG)}|run\.json|{_TMP_RES['.'].pattern}")


class RunStore:
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

    def create(self, cfg: RunConfig) -> None:
        self.check_new()
        try:
            self.root.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise StoreError(f"cannot create run directory {self.root}: {exc.strerror or exc}") from None
        self._check_writable()
        atomic_write_text(self.run_json, json.dumps({"run_id": uuid.uuid4().hex[:16]}))  # before the config:
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
        return build_config(read_yaml(self.config_path))

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
        arrays = {k: np.asarray(v) for k, v in arrays.items()} | bind(self.run_id(), generation)
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        atomic_write_bytes(self.ckpt_dir / f"{name}.npz", buf.getvalue())
        atomic_write_text(self.ckpt_dir / f"{name}.json", json.dumps({**meta, "generation": generation,
                                                                      DIGEST_KEY: arrays_digest(arrays)}))
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
            data = json.loads(read_regular(latest).decode("utf-8"))
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
        older = self.fallback_hint(g)
        try:
            meta = json.loads(read_regular(self.ckpt_dir / f"{name}.json").decode("utf-8"))
            with np.load(io.BytesIO(read_regular(self.ckpt_dir / f"{name}.npz")), allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            why = type(exc).__name__
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} is unreadable ({why}){older}") from None
        if not isinstance(meta, dict) or type(meta.get("generation")) is not int or meta["generation"] != g:
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} is unreadable (its .json is not this "
                             f"checkpoint's metadata){older}")
        why = self._foreign(arrays, meta, g)
        if why:
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} {why}{older}")
        return {k: v for k, v in arrays.items() if not k.startswith(BIND_PREFIX)}, meta

    def fallback_hint(self, g: int) -> str:
        """``; delete gen_G.npz and gen_G.json to resume from gen_F`` (the newest checkpoint before ``g``),
        or "" without one: what to do when checkpoint ``g`` cannot be taken."""
        older = [x for x in self.checkpoints() if x < g]
        name = f"gen_{g:06d}"
        return f"; delete {name}.npz and {name}.json to resume from gen_{older[-1]:06d}" if older else ""

    def _foreign(self, arrays: dict[str, np.ndarray], meta: dict, g: int) -> str | None:
        """Why generation ``g``'s checkpoint (``arrays`` and ``meta`` as loaded) is not this run's own,
        or None: its arrays must name this run and generation ``g`` (:func:`bind`) and hash to the digest
        its ``.json`` holds. A checkpoint made before checkpoints were bound has neither (taken as is)."""
        bound = {k for k in arrays if k.startswith(BIND_PREFIX)}
        if not bound and DIGEST_KEY not in meta:
            return None
        if bound != {RUN_KEY, GEN_KEY} or not isinstance(meta.get(DIGEST_KEY), str):
            return "has arrays and metadata that were not saved together (one of its files replaced?)"
        rid, gen = arrays[RUN_KEY], arrays[GEN_KEY]
        if rid.dtype.kind != "U" or rid.shape != () or gen.dtype.kind != "i" or gen.shape != ():
            return "has malformed binding arrays (checkpoint/run_id, checkpoint/generation)"
        if str(rid) != (self.run_id() or ""):
            return f"holds the arrays of another run (run {str(rid) or 'without an id'}, not {self.run_id()})"
        if int(gen) != g:
            return f"holds generation {int(gen)}'s arrays, not generation {g}'s (an older checkpoint renamed?)"
        if arrays_digest(arrays) != meta[DIGEST_KEY]:
            return "holds arrays that are not the ones its .json was saved with (sha256 differs: edited or replaced?)"
        return None

    # -- resume ------------------------------------------------------------------------------------
    def clean_temporaries(self) -> list[Path]:
        """Delete ``.*.tmp`` files a killed writer left in the run directory (and its sub-directories)
        and checkpoint files without their pair; returns what was deleted. Only for the lock holder."""
        removed = []
        for folder, pattern in _TMP_RES.items():
            for d in self._run_folders(folder):
                for p in _listdir(d):
                    if pattern.fullmatch(p.name) and p.is_file() and not p.is_symlink():
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

    def check_writable_layout(self, columns: tuple[str, ...], tensorboard: bool) -> None:
        """What a run (a resume) will write to, checked before it writes anything (``StoreError``, one
        line, nothing changed): its files are regular files (not named pipes), ``metrics.csv`` has every column the run's rows fill (a cut header would
        fail at the first row, after a checkpoint was pruned), and ``figures/``, ``tb/`` (with
        ``tensorboard``) and ``checkpoints/`` are folders where they exist."""
        header = metrics_csv.read_table(self.metrics_path, repeats_ok=True)[0]  # validates it (resume repairs repeats)
        missing = [c for c in columns if header and c not in header]
        if missing:
            raise StoreError(f"{self.metrics_path} lacks the columns {missing} this run's rows fill (its header "
                             f"was cut?); restore it to resume")
        for f in (self.run_json, self.error_log, self.root / "wandb_id", self.ckpt_dir / "latest.json"):
            check_regular(f)  # a named pipe would make a read or an append wait forever
        for d in [self.figures_dir, self.ckpt_dir] + ([self.root / "tb"] if tensorboard else []):
            if d.exists() and not d.is_dir():
                raise StoreError(f"{d} is not a folder (the run writes {d.name}/ there); move it away to resume")

    def _run_folders(self, folder: str) -> list[Path]:
        """The folders ``folder`` (a :data:`RUN_FILES` key) stands for: ``trajectories/*`` is each of
        ``trajectories/gen_NNNNNN``; only real folders (a symlink is not followed)."""
        if folder.endswith("/*"):
            parent = self.root / folder[:-2]
            found = [p for p in _listdir(parent) if _CKPT_RE.fullmatch(p.name)] if _real_dir(parent) else []
        elif folder == ".":
            return [self.root] if self.root.is_dir() else []
        else:
            found = [self.root / folder]
        return [p for p in found if _real_dir(p)]

    def recover(self, loaded: Any = ...) -> tuple[dict[str, np.ndarray], dict] | None:
        """Make the run directory consistent before a writer continues it (call with the lock held):
        :meth:`prepare_recovery`, then its repair at once; returns the checkpoint it took."""
        loaded, repair = self.prepare_recovery(loaded)
        repair()
        return loaded

    def prepare_recovery(self, loaded: Any = ...):
        """Check what :meth:`recover` repairs and delete what a killed writer left (temporaries, half
        checkpoints: nothing a run reads); returns ``(loaded, repair)``: the newest complete checkpoint
        (``load_checkpoint``, or ``loaded``, what it returned) and the function that points
        ``latest.json`` at it and keeps the metrics rows it covers (every row without a checkpoint; the
        rows still waiting for test episodes when it was written are written again), one per generation:
        repeated rows, which two writers at once leave, are reduced to the last of each (with a warning).
        The run loop calls ``repair`` once its first generation ran, so a resume that fails before
        changes no saved file. ``StoreError``, with nothing changed, if rows it covers are missing (a
        deleted ``metrics.csv``)."""
        self._check_writable()
        if loaded is ...:
            loaded = self.load_checkpoint()  # validates before anything is changed
        cut = _rows_covered(loaded) - 1
        header, rows, repeats = metrics_csv.rows_up_to(self.metrics_path, cut)  # validates too
        missing = sorted(set(range(cut + 1)) - {int(r["generation"]) for r in rows})
        if missing:  # deleted or cut by hand: going on would lose them without a word
            what = f"lacks the rows of generations {_span(missing)}" if self.metrics_path.exists() else \
                "is missing"
            raise StoreError(f"{self.metrics_path} {what} (checkpoint gen_{loaded[1]['generation']:06d} covers "
                             f"generations {_span(list(range(cut + 1)))}); restore it to resume, which would go "
                             f"on without those rows (evaluate and render work as the run is)")
        self.clean_temporaries()

        def repair() -> None:
            if loaded is None:
                if self.ckpt_dir.is_dir():
                    (self.ckpt_dir / "latest.json").unlink(missing_ok=True)
            elif self._latest_named() != loaded[1]["generation"]:
                name = f"gen_{loaded[1]['generation']:06d}"
                atomic_write_text(self.ckpt_dir / "latest.json", json.dumps({"name": name}))
            metrics_csv.write_rows(self.metrics_path, header, rows)
            if repeats:
                warnings.warn(f"{self.metrics_path} held {repeats} repeated rows (two writers at once?); kept "
                              f"the last row of each generation", StoreWarning, stacklevel=3)

        return loaded, repair

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


def bind(run_id: str | None, generation: int) -> dict[str, np.ndarray]:
    """The arrays that bind a checkpoint's ``.npz`` to its run and generation (no pickle: a str and an
    int64 scalar)."""
    return {RUN_KEY: np.array(run_id or ""), GEN_KEY: np.array(generation, dtype=np.int64)}


def arrays_digest(arrays: dict[str, np.ndarray]) -> str:
    """sha256 of every array (name, dtype, shape, bytes, in name order): the ``.json``'s proof that the
    ``.npz`` beside it is the one saved with it."""
    h = hashlib.sha256()
    for k in sorted(arrays):
        a = np.ascontiguousarray(arrays[k])
        h.update(json.dumps([k, a.dtype.str, list(a.shape)]).encode())
        h.update(a.tobytes())
    return h.hexdigest()


def _real_dir(p: Path) -> bool:
    return p.is_dir() and not p.is_symlink()


def _listdir(d: Path) -> list[Path]:
    try:
        return sorted(d.iterdir())
    except OSError:
        return []


def _rows_covered(loaded) -> int:
    """Generations whose metrics rows a checkpoint (``load_checkpoint``'s answer) covers: all it ran,
    less the rows that still waited for their test episodes (None: no checkpoint, no rows)."""
    if loaded is None:
        return 0
    meta = loaded[1]
    waiting = [r.get("generation") for r in meta.get("waiting_rows") or [] if isinstance(r, dict)]
    waiting = [int(x) for x in waiting if isinstance(x, int)]
    return min(waiting) if waiting else int(meta["generation"])


def _span(gens: list[int]) -> str:
    """``0-3`` for consecutive generations, else the first few listed."""
    if gens == list(range(gens[0], gens[-1] + 1)):
        return f"{gens[0]}-{gens[-1]}" if len(gens) > 1 else str(gens[0])
    return ", ".join(map(str, gens[:5])) + (", ..." if len(gens) > 5 else "")
