"""Replacing a run directory that holds no checkpoint (a benchmark rerun whose settings changed for a run that
never checkpointed): only the files a run writes there, by name and folder, are deleted, and only when nothing
else is there. A file of any other name (a user's notes beside the run, a backup copy), a symlink or a folder the
run does not make refuses the replacement in one line with nothing deleted: a run never deletes what it did not
write.
"""

from __future__ import annotations

import re
from pathlib import Path

from shaped_es.rundir.atomic import StoreError
from shaped_es.rundir.recovery import DATA_DIRS, RUN_FILES

# the names a run writes, folder by folder: rundir/recovery.py's RUN_FILES, with the run's lock and error log, its
# figure, TensorBoard's events and the videos; each name's temporaries too (``.NAME.RANDOM.tmp``:
# atomic_write_bytes' and the trajectory store's)
_WRITTEN = {
    ".": RUN_FILES["."] + r"|\.lock|error\.log",
    "checkpoints": RUN_FILES["checkpoints"],
    "mphi_data*": RUN_FILES["mphi_data"],  # each of prune's DATA_DIRS (M_phi's and its rivals')
    "trajectories/gen_*": RUN_FILES["trajectories/*"],
    "trajectories": r"(?!)",  # folders only
    "tb": r"events\.out\.tfevents\.[^/]+",
    "figures": RUN_FILES["figures"],
    "videos": r"gen_\d{6,}\.gif",
}
_FILE_RES = {k: re.compile(rf"(?:{v})|\.(?:{v})\.[A-Za-z0-9_]+\.tmp") for k, v in _WRITTEN.items()}
_TOP_FOLDERS = {"checkpoints", "trajectories", "tb", "figures", "videos"}
_GEN_FOLDER = re.compile(r"gen_\d{6,}")


def _kind(rel: Path) -> str | None:
    """The ``_WRITTEN`` key of a run-made folder at ``rel`` (relative to the run directory), else None."""
    parts = rel.parts
    if len(parts) == 1:
        if parts[0] in DATA_DIRS:
            return "mphi_data*"
        return parts[0] if parts[0] in _TOP_FOLDERS else None
    if len(parts) == 2 and parts[0] == "trajectories" and _GEN_FOLDER.fullmatch(parts[1]):
        return "trajectories/gen_*"
    return None


def foreign_entries(root: Path) -> list[Path]:
    """What in the run directory ``root`` no run wrote (sorted; symlinks are never followed and count as
    foreign); ``[]``: every entry is a run's."""
    foreign: list[Path] = []

    def walk(folder: Path, key: str) -> None:
        for p in sorted(folder.iterdir()):
            rel = p.relative_to(root)
            if p.is_symlink():
                foreign.append(p)
            elif p.is_dir():
                sub = _kind(rel)
                (walk(p, sub) if sub is not None else foreign.append(p))
            elif not _FILE_RES[key].fullmatch(p.name):
                foreign.append(p)

    walk(root, ".")
    return foreign


def replace_run_dir(root: Path) -> None:
    """Delete the run directory ``root`` for a fresh start when it holds only what a run writes (files first,
    then the folders, deepest first); ``StoreError`` naming what else is there, with nothing deleted."""
    try:
        foreign = foreign_entries(root)
    except OSError as exc:
        raise StoreError(f"cannot list {root}: {exc.strerror or exc}") from None
    if foreign:
        shown = ", ".join(str(p.relative_to(root)) for p in foreign[:3]) + (", ..." if len(foreign) > 3 else "")
        raise StoreError(f"{root} holds a run with other settings and no checkpoint, to be started again, but also "
                         f"files no run writes ({shown}); move them away (or the folder) and rerun, or use another "
                         f"--out")
    folders = sorted((p for p in root.rglob("*") if p.is_dir()), key=lambda p: len(p.parts), reverse=True)
    for p in root.rglob("*"):
        if p.is_file():
            p.unlink()
    for d in folders:
        d.rmdir()
    root.rmdir()
