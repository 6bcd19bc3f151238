"""The trajectory store: the paper's shared NFS, onto which every worker writes its rollouts (Sec. IV).

One Parquet shard per generation and writer: all members one writer holds, in member order::

    ROOT/gen_{g:06d}/members_{first:04d}-{last:04d}.parquet

``ROOT`` is one run's (:func:`run_root`): ``RUN/trajectories`` by default, or ``SHARED/run_{id}`` under a
``shaping.trajectory_root`` that several runs share, so that they never read each other's shards. A shard
written under a ``run_{id}`` directory records that id, and a shard read there must carry the same one.

On one machine the trainer writes one shard per generation (all 64 members, in a background thread);
on a cluster each worker writes one shard for its chunk of members. Readers do not care which.

A shard's columns and metadata, and their encoding to and from an Arrow table with every check on read, are
``shaping/shard_table.py``'s; this module lays the shards out, writes, reads, lists and deletes them.

``ROOT`` is a local path or any URI ``pyarrow.fs.FileSystem.from_uri`` understands (``file://``,
``s3://``, ...). Writes are atomic: a temporary file in the same directory, then a rename, so a reader
sees a complete shard or none. Shards carry page checksums; a missing column, a wrong type, a null or a
checksum mismatch on read raises :class:`TrajectoryStoreError` (one line naming the file). Never pickle.

The master reads a whole generation to train ``M_phi`` (:func:`read_generation`); a member's history
``D_i`` (DAgger-style aggregation over generations, Algorithm 1) comes from :func:`read_members`, which
reads each needed shard once.
"""

from __future__ import annotations

import os
import re
import uuid
import warnings
from collections.abc import Iterable, Sequence
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.fs as pafs
import pyarrow.parquet as pq

from shaped_es.data import PackedTransitions, Transitions
from shaped_es.shaping.shard_table import TrajectoryStoreError, from_table, packed_table, to_table

_SHARD_RE = re.compile(r"^members_(\d{4,})-(\d{4,})\.parquet$")
_TMP_RE = re.compile(r"^\.members_\d{4,}-\d{4,}\.parquet\.[A-Za-z0-9_]+\.tmp$")  # write_shard's, before its rename
_GEN_RE = re.compile(r"^gen_(\d{6,})$")


_RUN_DIR_RE = re.compile(r"^run_([0-9a-f]{16,64})$")


class TrajectoryStoreWarning(UserWarning):
    """The store cannot keep a run's shards apart from other runs' (printed as one line)."""


def run_root(shared: str | None, default: str, run_id: str | None) -> str:
    """Where one run's shards go: ``default`` (``RUN/trajectories``, the run's own) without a ``shared``
    root; under one, ``shared/run_{run_id}``. A run made before runs had ids keeps ``shared`` itself (so
    it stays resumable), with a warning that its shards are not kept apart from other runs'."""
    if shared is None:
        return default
    if run_id is None:
        warnings.warn(f"this run has no run id (it predates them), so its trajectory shards in {shared} are "
                      f"not kept apart from other runs': run no other run on that trajectory_root",
                      TrajectoryStoreWarning, stacklevel=2)
        return shared
    return _join(shared, f"run_{run_id}")


def _owner(root_or_shard_dir: str) -> bytes | None:
    """The run id a ``run_{id}`` directory name gives (None elsewhere)."""
    m = _RUN_DIR_RE.match(os.path.basename(os.fspath(root_or_shard_dir).rstrip("/")))
    return m.group(1).encode() if m else None


def _resolve(where: str | os.PathLike) -> tuple[pafs.FileSystem, str]:
    s = os.fspath(where)
    if "://" in s:
        fs, path = pafs.FileSystem.from_uri(s)
        return fs, path.rstrip("/")
    return pafs.LocalFileSystem(), os.path.abspath(s)


def _join(root: str | os.PathLike, *parts: str) -> str:
    s = os.fspath(root)
    return "/".join([s.rstrip("/"), *parts]) if "://" in s else os.path.join(s, *parts)


def shard_path(root: str | os.PathLike, generation: int, first: int, last: int | None = None) -> str:
    """``ROOT/gen_{g:06d}/members_{first:04d}-{last:04d}.parquet`` (a URI when ``root`` is one)."""
    last = first if last is None else last
    return _join(root, f"gen_{generation:06d}", f"members_{first:04d}-{last:04d}.parquet")


def write_shard(root: str | os.PathLike, transitions: Transitions | Sequence[Transitions] | PackedTransitions,
                stacked: Transitions | None = None) -> str:
    """Write the transitions of one or more members of one generation atomically, as one shard (members
    in ascending order); returns the shard's path. ``transitions``: one member's, a list, or a block of
    members (``data.PackedTransitions``, written from its arrays as they are). ``stacked``: the list's
    members already concatenated in that order (``data.concat_members``), used instead of concatenating
    again."""
    if isinstance(transitions, PackedTransitions):
        block = transitions
        if len(block.members) == 0:
            raise TrajectoryStoreError("cannot write an empty shard (no members)")
        if (np.diff(block.members) <= 0).any():
            raise TrajectoryStoreError("a shard holds distinct members of one generation, ascending")
        table = packed_table(block, _owner(root))
        generation, first, last = block.generation, int(block.members[0]), int(block.members[-1])
    else:
        given = [transitions] if isinstance(transitions, Transitions) else list(transitions)
        trs = sorted(given, key=lambda t: t.member)
        if stacked is not None and [t.member for t in given] != [t.member for t in trs]:
            stacked = None  # not in member order: concatenate here
        if not trs:
            raise TrajectoryStoreError("cannot write an empty shard (no members)")
        if len({t.generation for t in trs}) > 1 or len({t.member for t in trs}) < len(trs):
            raise TrajectoryStoreError("a shard holds distinct members of one generation")
        table = to_table(trs, stacked, _owner(root))
        generation, first, last = trs[0].generation, trs[0].member, trs[-1].member
    dest = shard_path(root, generation, first, last)
    fs, path = _resolve(dest)
    parent, name = path.rsplit("/", 1) if not isinstance(fs, pafs.LocalFileSystem) else os.path.split(path)
    tmp = f"{parent}/.{name}.{uuid.uuid4().hex}.tmp"
    # no dictionary pages: float columns have no repeats (4.6x faster to write: 14 vs 64 ms for a
    # generation of 27k CarNav steps); lz4 without column statistics: 18 vs 26 ms of CPU for zstd
    # (which is ~10% smaller), the shard is one row group and is always read whole (measured); vectors as
    # fixed_size_binary (format 2): 9 vs 28 ms of CPU for 39k CarNav-v0 steps, read 3 vs 17 ms (measured)
    opts = dict(compression="lz4", use_dictionary=False, write_statistics=False, write_page_checksum=True)
    try:
        fs.create_dir(parent, recursive=True)
        if isinstance(fs, pafs.LocalFileSystem):
            try:
                with open(tmp, "wb") as fh:
                    pq.write_table(table, fh, **opts)
                    fh.flush()
                    os.fsync(fh.fileno())
                os.replace(tmp, path)
            finally:
                if os.path.exists(tmp):
                    os.unlink(tmp)
        else:
            pq.write_table(table, tmp, filesystem=fs, **opts)
            fs.move(tmp, path)
    except (OSError, pa.ArrowException) as exc:
        raise TrajectoryStoreError(f"cannot write trajectory shard {dest}: {_first_line(exc)}") from None
    return dest


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0] if text else ''}"


def _damaged_hint(path: str | os.PathLike) -> str:
    """What to do about a damaged shard of a run's generation folder (a shard is written whole and renamed, so
    a crash leaves none half-written): restore it, or resume from a checkpoint taken before its generation ran,
    which does not read it ("" outside a ``gen_NNNNNN`` folder)."""
    m = re.fullmatch(r"gen_(\d{6,})", Path(os.fspath(path)).parent.name)
    if m is None:
        return ""
    return (f"; restore it from a copy, or resume from checkpoint gen_{m.group(1)} or older (move the newer ones "
            f"out of RUN/checkpoints), which does not read it")


def read_shard(path: str | os.PathLike) -> list[Transitions]:
    """Read and validate one shard: one :class:`Transitions` per member, ascending (schema above)."""
    fs, p = _resolve(path)
    try:
        table = pq.read_table(p, filesystem=fs, page_checksum_verification=True)
    except FileNotFoundError:
        raise TrajectoryStoreError(f"trajectory shard not found: {path}") from None
    except (OSError, pa.ArrowException, ValueError) as exc:
        raise TrajectoryStoreError(f"corrupt trajectory shard {path}: {_first_line(exc).rstrip('.')}"
                                   f"{_damaged_hint(path)}") from None
    where = os.fspath(path)
    owner = _owner(os.path.dirname(os.path.dirname(where.rstrip("/"))))  # ROOT of ROOT/gen_N/members_*
    return from_table(table, where, owner)


def _listdir(fs: pafs.FileSystem, path: str) -> list[pafs.FileInfo]:
    try:
        return fs.get_file_info(pafs.FileSelector(path, allow_not_found=True))
    except (OSError, pa.ArrowException) as exc:
        raise TrajectoryStoreError(f"cannot list {path}: {_first_line(exc)}") from None


def list_generations(root: str | os.PathLike) -> list[int]:
    """Generations that have a directory in the store, ascending."""
    fs, p = _resolve(root)
    found = [_GEN_RE.match(i.base_name) for i in _listdir(fs, p) if i.type == pafs.FileType.Directory]
    return sorted(int(m.group(1)) for m in found if m)


def _shards(root: str | os.PathLike, generation: int) -> list[tuple[int, int, str]]:
    """``(first, last, path)`` of every shard of one generation, by first member."""
    gen_dir = _join(root, f"gen_{generation:06d}")
    fs, p = _resolve(gen_dir)
    found = [_SHARD_RE.match(i.base_name) for i in _listdir(fs, p) if i.type == pafs.FileType.File]
    spans = sorted((int(m.group(1)), int(m.group(2))) for m in found if m)
    return [(a, b, shard_path(root, generation, a, b)) for a, b in spans]


def read_generation(root: str | os.PathLike, generation: int) -> list[Transitions]:
    """Every member's transitions of one generation, by member index (``[]`` if the generation has none)."""
    out = [tr for _, _, path in _shards(root, generation) for tr in read_shard(path)]
    return sorted(out, key=lambda t: t.member)


def read_members(
    root: str | os.PathLike, members: Iterable[int], generations: Iterable[int]
) -> dict[int, list[Transitions]]:
    """Each member's aggregated data set ``D_i`` (DAgger-style): its transitions of ``generations``,
    oldest first; every shard needed is read once. Generations without data for a member are skipped."""
    want = sorted(set(int(m) for m in members))
    out: dict[int, list[Transitions]] = {m: [] for m in want}
    for g in sorted(set(int(g) for g in generations)):
        for first, last, path in _shards(root, g):
            if any(first <= m <= last for m in want):
                for tr in read_shard(path):
                    if tr.member in out:
                        out[tr.member].append(tr)
    return out


def read_member_history(
    root: str | os.PathLike, member: int, generations: Iterable[int], last: int | None = None
) -> list[Transitions]:
    """Member ``i``'s ``D_i``: its transitions of ``generations``, oldest first, restricted to the
    ``last`` newest of them when given."""
    gens = sorted(set(int(g) for g in generations))
    if last is not None:
        gens = gens[-last:] if last > 0 else []
    return read_members(root, [member], gens)[int(member)]


def delete_generations(root: str | os.PathLike, generations: Iterable[int]) -> None:
    """Remove generations from the store (disk budget, or shards a killed run wrote past its last checkpoint):
    the files the store writes (shards, and the temporary files of a write cut short), then the generation's
    directory if nothing else is left in it -- a file a user put there is kept, and so is its directory.
    Missing generations are ignored."""
    for g in generations:
        fs, p = _resolve(_join(root, f"gen_{int(g):06d}"))
        if fs.get_file_info(p).type != pafs.FileType.Directory:
            continue
        entries = _listdir(fs, p)
        ours = [i for i in entries if i.type == pafs.FileType.File
                and (_SHARD_RE.fullmatch(i.base_name) or _TMP_RE.fullmatch(i.base_name))]
        for i in ours:
            fs.delete_file(i.path)
        if len(ours) == len(entries):
            fs.delete_dir(p)
