"""Pruning a finished run (``shaped-es prune``): delete what only an exact resume reads, keep what
``evaluate``, ``render``, ``report`` and ``load_policy`` read.

What goes, by name only, inside a run directory (a folder whose ``config.yaml`` reads as a run's config),
and only the files the run writes there (a symlink is never followed; a file of another name stays, and
so does its folder):

- ``mphi_data/`` and the rivals' ``mphi_data_rival/``, ``mphi_data_servo/``, ``mphi_data_shoot/``,
  ``mphi_data_shoot_base/``: the data parts ``added_NNNNNN.npz`` that rebuild M_phi's data sets on resume;
- ``trajectories/gen_NNNNNN/members_*.parquet``: the recorded steps' shards (shards under a shared
  ``shaping.trajectory_root`` are not in the run directory, and are left as they are);
- ``checkpoints/gen_NNNNNN.npz`` / ``.json`` older than the newest complete checkpoint (``keep_checkpoints``).

What stays: the newest checkpoint and ``latest.json``, ``config.yaml``, ``run.json``, ``metrics.csv``,
``label_probe.json``, ``label_probe_candidate.npy``, ``figures/``, ``tb/``, ``videos/``, logs.

A run whose data parts or shards went can no longer be resumed exactly: it is marked by ``RUN/pruned.json``
(written before anything is deleted, so a prune cut short leaves a marked run), and :func:`refuse_pruned`
(``resume``, the run loop's restore) refuses it in one line. A run that lost only older checkpoints (a
Vanilla-ES run) stays resumable and unmarked. Only a finished run is pruned (``force``: an unfinished one
too), never one another process holds (its lock), never one without a checkpoint.
"""

from __future__ import annotations

import json
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from shaped_es.config import ConfigError, RunConfig
from shaped_es.rundir.atomic import StoreError, atomic_write_text, entries, read_regular, real_dir
from shaped_es.rundir.lock import holder
from shaped_es.rundir.recovery import DATA_DIRS
from shaped_es.rundir.store import RunStore

PRUNED_NAME = "pruned.json"
TRAJECTORIES = "trajectories"
_TMP = r"\.[A-Za-z0-9_]+\.tmp"  # atomic_write_bytes' (and the trajectory store's) temporaries
_PART_RE = re.compile(rf"added_\d{{6,}}\.npz|\.added_\d{{6,}}\.npz{_TMP}")
_SHARD_RE = re.compile(rf"members_\d{{4,}}-\d{{4,}}\.parquet|\.members_\d{{4,}}-\d{{4,}}\.parquet{_TMP}")
_GEN_RE = re.compile(r"gen_\d{6,}")  # trajectories/gen_NNNNNN/
_CKPT_FILE_RE = re.compile(r"(gen_(\d{6,}))\.(?:npz|json)")


@dataclass
class PrunePlan:
    """What pruning a run deletes: ``files`` (their ``nbytes``), then ``folders`` where they are left empty
    (deepest first); ``parts`` names them for people; ``resume_data``: data parts or shards among them (the
    run is marked and no longer resumes); ``foreign``: files of other names inside those folders (kept)."""

    files: list[Path] = field(default_factory=list)
    folders: list[Path] = field(default_factory=list)
    nbytes: int = 0
    parts: list[str] = field(default_factory=list)
    resume_data: bool = False
    foreign: list[Path] = field(default_factory=list)


@dataclass
class PruneResult:
    """One run's outcome: ``status`` is ``pruned``, ``would prune`` (a dry run), ``nothing`` (nothing left
    to delete) or ``skipped`` (``why``); ``nbytes`` freed (or that would be), ``parts`` what, ``notes``
    what else to know (files kept, a shared trajectory root, already pruned, still resumable)."""

    root: Path
    status: str
    nbytes: int = 0
    parts: list[str] = field(default_factory=list)
    why: str = ""
    notes: list[str] = field(default_factory=list)


def _own_file(p: Path) -> bool:
    return not p.is_symlink() and p.is_file()


def plan_prune(store: RunStore) -> PrunePlan:
    """What :func:`prune_run` deletes in ``store``'s run directory (nothing is changed here)."""
    plan, root = PrunePlan(), store.root

    def take(p: Path) -> None:
        plan.files.append(p)
        plan.nbytes += p.lstat().st_size

    for name in DATA_DIRS:
        d = root / name
        if not real_dir(d):
            continue
        before = len(plan.files)
        for p in entries(d):
            (take if _PART_RE.fullmatch(p.name) and _own_file(p) else plan.foreign.append)(p)
        plan.folders.append(d)
        if len(plan.files) > before:
            plan.parts.append(f"{name}/")
            plan.resume_data = True
    traj = root / TRAJECTORIES
    if real_dir(traj):
        before = len(plan.files)
        for gen in entries(traj):
            if not (_GEN_RE.fullmatch(gen.name) and real_dir(gen)):
                plan.foreign.append(gen)
                continue
            for p in entries(gen):
                (take if _SHARD_RE.fullmatch(p.name) and _own_file(p) else plan.foreign.append)(p)
            plan.folders.append(gen)
        plan.folders.append(traj)
        if len(plan.files) > before:
            plan.parts.append(f"{TRAJECTORIES}/")
            plan.resume_data = True
    gens = store.checkpoints()
    if gens:
        older = set()
        for p in entries(store.ckpt_dir):
            m = _CKPT_FILE_RE.fullmatch(p.name)
            if m and int(m.group(2)) < gens[-1] and _own_file(p):
                take(p)
                older.add(m.group(1))
        if older:
            plan.parts.append(f"{len(older)} older checkpoint{'s' * (len(older) > 1)}")
    return plan


def pruned_record(store: RunStore) -> dict | None:
    """The run's ``pruned.json`` (``{}`` if unreadable: still pruned), None if the run was never pruned."""
    path = store.root / PRUNED_NAME
    if not path.exists():
        return None
    try:
        data = json.loads(read_regular(path).decode("utf-8"))
    except (OSError, ValueError, StoreError):
        return {}
    return data if isinstance(data, dict) else {}


def refuse_pruned(store: RunStore) -> None:
    """``StoreError`` (one line) if the run was pruned: what an exact resume rebuilds from is gone."""
    record = pruned_record(store)
    if record is None:
        return
    when = f" on {record['pruned_at']}" if isinstance(record.get("pruned_at"), str) else ""
    raise StoreError(f"{store.root} was pruned{when} (shaped-es prune deleted the M_phi data parts and "
                     f"trajectory shards an exact resume rebuilds from), so it cannot be resumed or extended; "
                     f"evaluate, render and report use it as it is, and 'shaped-es train --config "
                     f"{store.config_path} --generations G --out NEW' runs it again for longer")


def prune_run(root: str | Path, finished: Callable[[RunConfig, RunStore], bool], *, force: bool = False,
              dry_run: bool = False) -> PruneResult:
    """Prune the run at ``root`` if ``finished(cfg, store)`` says it is finished (``force``: also if not);
    ``dry_run``: say what would go, change nothing. Skipped (``PruneResult.why``): not a run directory,
    held by another process, no readable checkpoint, unfinished without ``force``. ``OSError`` of a
    deletion propagates (the run is marked by then)."""
    store = RunStore(root)
    try:
        cfg = store.read_config()
    except (StoreError, ConfigError, OSError, ValueError) as exc:
        return PruneResult(store.root, "skipped", why=_first_line(exc))
    if dry_run:
        if (who := holder(store.root)) is not None:
            return PruneResult(store.root, "skipped", why=who)
        return _judge(store, cfg, finished, force, dry_run=True)
    try:
        with store.lock():  # no resume starts while the files go
            return _judge(store, cfg, finished, force, dry_run=False)
    except StoreError as exc:  # another process holds it
        return PruneResult(store.root, "skipped", why=_first_line(exc))


def _judge(store: RunStore, cfg: RunConfig, finished, force: bool, dry_run: bool) -> PruneResult:
    try:
        meta = store.checkpoint_meta()  # the newest checkpoint, checked: the one kept must be readable
    except StoreError as exc:
        return PruneResult(store.root, "skipped", why=_first_line(exc))
    if meta is None:
        return PruneResult(store.root, "skipped", why="it has no checkpoint yet (nothing to evaluate, nothing pruned)")
    done = int(meta["generation"])
    if not force and not finished(cfg, store):
        return PruneResult(store.root, "skipped",
                           why=f"unfinished ({done} of {cfg.generations} generations done): resume it, or "
                               f"--force prunes it as it is (it then cannot be resumed)")
    plan = plan_prune(store)
    notes = []
    if plan.foreign:
        shown = ", ".join(str(p.relative_to(store.root)) for p in plan.foreign[:3])
        notes.append(f"kept {len(plan.foreign)} file(s) the run did not write ({shown}"
                     f"{', ...' if len(plan.foreign) > 3 else ''})")
    shared = getattr(getattr(cfg, "shaping", None), "trajectory_root", None)
    if shared is not None:
        notes.append(f"its trajectory shards under shaping.trajectory_root {shared} are left as they are")
    old = pruned_record(store)
    if not plan.files:
        notes.append("already pruned" if old is not None else "nothing to prune")
        return PruneResult(store.root, "nothing", notes=notes)
    if not plan.resume_data and old is None:
        notes.append("it stays resumable (only older checkpoints go)")
    elif dry_run and plan.resume_data:  # said before it happens (a new user read the dry run as harmless)
        notes.append("resume would refuse it afterwards (evaluate, render and report still work)")
    if dry_run:
        return PruneResult(store.root, "would prune", plan.nbytes, plan.parts, notes=notes)
    if plan.resume_data or old is not None:  # marked first: a prune cut short leaves a marked run
        record = {"pruned_at": time.strftime("%Y-%m-%dT%H:%M:%S"), "generation": done,
                  "deleted": plan.parts, "freed_bytes": plan.nbytes}
        if old:
            record.update(pruned_at=old.get("pruned_at", record["pruned_at"]),
                          deleted=list(dict.fromkeys([*old.get("deleted", []), *plan.parts])),
                          freed_bytes=int(old.get("freed_bytes", 0) or 0) + plan.nbytes)
        atomic_write_text(store.root / PRUNED_NAME, json.dumps(record))
    for p in plan.files:
        p.unlink(missing_ok=True)
    for d in plan.folders:  # deepest first: gen_N/ before trajectories/
        try:
            d.rmdir()
        except OSError:  # not empty: it holds files the run did not write
            pass
    return PruneResult(store.root, "pruned", plan.nbytes, plan.parts, notes=notes)


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return text[0] if text else type(exc).__name__
