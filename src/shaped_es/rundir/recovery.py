"""What a run directory needs before a writer continues it (resume): the temporaries and half checkpoints
a killed writer left deleted (in the folders of :data:`RUN_FILES` only), its files checked before
anything is written, ``latest.json`` pointed at the checkpoint taken and the metrics rows it covers kept.

:class:`Recovery` is :class:`~shaped_es.rundir.store.RunStore`'s part that does this (it uses the
store's paths, ``load_checkpoint``, ``_latest_named`` and ``_check_writable``).
"""

from __future__ import annotations

import json
import os
import re
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from shaped_es.rundir import metrics_csv
from shaped_es.rundir.atomic import StoreError, StoreWarning, atomic_write_text, check_regular, entries, real_dir
from shaped_es.rundir.checkpoints import _CKPT_RE

# What the run writes, folder by folder (relative to the run directory; ``*`` a ``gen_NNNNNN`` folder):
# clean-up deletes only the temporaries of these names (``.NAME.RANDOM.tmp``: atomic_write_bytes' and the
# trajectory store's), never walking any other folder, so a run directory holds nothing else of value to it
# the data-part folders of M_phi and its rivals (guides/shaped.py, guides/rival.py name them)
DATA_DIRS = ("mphi_data", "mphi_data_rival", "mphi_data_servo", "mphi_data_shoot", "mphi_data_shoot_base",
             "mphi_data_shoot_third")
RUN_FILES = {
    ".": r"config\.yaml|run\.json|metrics\.csv|wandb_id|label_probe\.json|label_probe_candidate\.npy|pruned\.json"
         r"|position_period\.json",
    "checkpoints": r"gen_\d{6,}\.(?:npz|json)|latest\.json",
    **{d: r"added_\d{6,}\.npz" for d in DATA_DIRS},
    "trajectories/*": r"members_\d{4,}-\d{4,}\.parquet",
    "figures": r"reward\.png",
}
_TMP_RES = {d: re.compile(rf"\.(?:{names})\.[A-Za-z0-9_]+\.tmp") for d, names in RUN_FILES.items()}


class Recovery:
    """The resume methods of :class:`~shaped_es.rundir.store.RunStore`."""

    def clean_temporaries(self) -> list[Path]:
        """Delete ``.*.tmp`` files a killed writer left in the run directory (and its sub-directories)
        and checkpoint files without their pair; returns what was deleted. Only for the lock holder."""
        removed = []
        for folder, pattern in _TMP_RES.items():
            for d in self._run_folders(folder):
                for p in entries(d):
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
            found = [p for p in entries(parent) if _CKPT_RE.fullmatch(p.name)] if real_dir(parent) else []
        elif folder == ".":
            return [self.root] if self.root.is_dir() else []
        else:
            found = [self.root / folder]
        return [p for p in found if real_dir(p)]

    def recover(self, loaded: Any = ...) -> tuple[dict[str, np.ndarray], dict] | None:
        """Make the run directory consistent before a writer continues it (call with the lock held):
        :meth:`prepare_recovery`, then its repair at once; returns the checkpoint it took."""
        loaded, repair = self.prepare_recovery(loaded)
        repair()
        return loaded

    def prepare_recovery(self, loaded: Any = ..., uncheckpointed: int | None = None):
        """Check what :meth:`recover` repairs and delete what a killed writer left (temporaries, half
        checkpoints: nothing a run reads); returns ``(loaded, repair)``: the newest complete checkpoint
        (``load_checkpoint``, or ``loaded``, what it returned) and the function that points
        ``latest.json`` at it and keeps the metrics rows it covers (every row without a checkpoint; the
        rows still waiting for test episodes when it was written are written again), one per generation:
        repeated rows, which two writers at once leave, are reduced to the last of each (with a warning).
        The run loop calls ``repair`` once its first generation ran, so a resume that fails before
        changes no saved file. ``StoreError``, with nothing changed, if rows it covers are missing (a
        deleted ``metrics.csv``), or if there is no checkpoint and ``metrics.csv`` holds rows past the first
        ``uncheckpointed`` generations (the first checkpoint's interval: more than a run killed before its
        first checkpoint leaves; its checkpoints were deleted, and going on would drop those rows)."""
        self._check_writable()
        if loaded is ...:
            loaded = self.load_checkpoint()  # validates before anything is changed
        if loaded is None and uncheckpointed is not None and self.metrics_path.exists():
            past = sorted({int(r["generation"]) for r in metrics_csv.read_table(self.metrics_path, repeats_ok=True)[1]})
            if past and past[-1] >= uncheckpointed:
                raise StoreError(f"{self.ckpt_dir} holds no checkpoint, but {self.metrics_path} holds the rows of "
                                 f"generations {_span(past)} (the run checkpoints every {uncheckpointed} "
                                 f"generation(s): were its checkpoints deleted?); restore them to resume, or move "
                                 f"{self.metrics_path.name} away to run again from generation 1")
        cut = rows_covered(loaded) - 1
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


def rows_covered(loaded) -> int:
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
