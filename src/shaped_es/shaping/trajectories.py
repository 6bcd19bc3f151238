"""The trajectory store: the paper's shared NFS, onto which every worker writes its rollouts (Sec. IV).

One Parquet shard per generation and writer: all members one writer holds, in member order::

    ROOT/gen_{g:06d}/members_{first:04d}-{last:04d}.parquet

``ROOT`` is one run's (:func:`run_root`): ``RUN/trajectories`` by default, or ``SHARED/run_{id}`` under a
``shaping.trajectory_root`` that several runs share, so that they never read each other's shards. A shard
written under a ``run_{id}`` directory records that id, and a shard read there must carry the same one.

On one machine the trainer writes one shard per generation (all 64 members, in a background thread);
on a cluster each worker writes one shard for its chunk of members. Readers do not care which.

========================================  ========================================================
column                                    type
========================================  ========================================================
``generation``                            int32 (constant in a shard; also in the schema metadata)
``member``                                int32 (ascending; the shard's members are in the metadata)
``episode``, ``step``                     int32
``state``                                 vector<obs_dim>
``position``, ``waypoint``                vector<d>
``action``                                vector<act_dim>
``reward``                                float32
``expert`` (optional)                     vector<act_dim>: the env controller's action at ``s_t``
                                          (``shaping.labels = controller``)
========================================  ========================================================

A ``vector<w>`` column is ``fixed_size_binary[4 w]``: each row's ``w`` little-endian float32 values as one
value (format 2, written since the shards went off the critical path: a plain column with no repetition
levels, 3x cheaper to write and 5x cheaper to read than format 1's ``fixed_size_list<float32>[w]``, which
readers still accept; read one as ``np.frombuffer(column.buffers()[1], "<f4").reshape(-1, w)``).

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

from shaped_es.data import COLUMNS, PackedTransitions, Transitions

INT_COLUMNS = ("generation", "member", "episode", "step")
VECTOR_COLUMNS = ("state", "position", "waypoint", "action")
EXPERT = "expert"  # optional vector column (data.Transitions.expert)
FORMAT_KEY, FORMAT_VERSION = b"shaped_es.trajectories", b"2"
READABLE_VERSIONS = (b"1", b"2")  # 1: vectors as fixed_size_list<float32>
RUN_KEY = b"run_id"
_SHARD_RE = re.compile(r"^members_(\d{4,})-(\d{4,})\.parquet$")
_TMP_RE = re.compile(r"^\.members_\d{4,}-\d{4,}\.parquet\.[A-Za-z0-9_]+\.tmp$")  # write_shard's, before its rename
_GEN_RE = re.compile(r"^gen_(\d{6,})$")


_RUN_DIR_RE = re.compile(r"^run_([0-9a-f]{16,64})$")


class TrajectoryStoreError(RuntimeError):
    """A trajectory shard is missing, corrupt or malformed, or cannot be written (message: one line)."""


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


def _to_table(trs: Sequence[Transitions], stacked: Transitions | None = None,
              run_id: bytes | None = None) -> pa.Table:
    g = trs[0].generation
    T = sum(len(t) for t in trs)
    cols: dict[str, pa.Array] = {
        "generation": pa.array(np.full(T, g, np.int32)),
        "member": pa.array(np.concatenate([np.full(len(t), t.member, np.int32) for t in trs])),
        "episode": pa.array(np.concatenate([np.asarray(t.episode, np.int32).reshape(len(t)) for t in trs])),
        "step": pa.array(np.concatenate([np.asarray(t.step, np.int32).reshape(len(t)) for t in trs])),
    }
    for name in VECTOR_COLUMNS:
        if stacked is not None and getattr(stacked, name).dtype == np.float32:  # already one array
            a = getattr(stacked, name)  # (T, w)
            if a.ndim == 2 and a.shape[0] == T and a.shape[1] > 0:
                cols[name] = _vector_column(a)
                continue
        parts = [np.asarray(getattr(t, name), dtype=np.float32) for t in trs]
        for t, a in zip(trs, parts):
            if a.ndim != 2 or a.shape[0] != len(t) or a.shape[1] == 0 or a.shape[1] != parts[0].shape[1]:
                raise TrajectoryStoreError(
                    f"cannot store member {t.member} generation {t.generation}: column '{name}' has shape "
                    f"{a.shape}, expected ({len(t)}, width > 0) (does the env provide info "
                    f"'position'/'waypoint'?)")
        cols[name] = _vector_column(np.concatenate(parts))  # (T, w)
    cols["reward"] = pa.array(np.concatenate([np.asarray(t.reward, np.float32).reshape(len(t)) for t in trs]))
    names = list(COLUMNS)
    if all(t.expert is not None for t in trs):  # the optional column: every member has it, or none
        cols[EXPERT] = _vector_column(np.concatenate([np.asarray(t.expert, np.float32).reshape(len(t), -1)
                                                      for t in trs]))  # (T, act)
        names.append(EXPERT)
    members = ",".join(str(t.member) for t in trs)
    meta = {FORMAT_KEY: FORMAT_VERSION, b"generation": str(g).encode(), b"members": members.encode()}
    if run_id is not None:
        meta[RUN_KEY] = run_id
    return pa.table({c: cols[c] for c in names}).replace_schema_metadata(meta)


def _packed_table(block: PackedTransitions, run_id: bytes | None = None) -> pa.Table:
    """The table :func:`_to_table` makes of ``block.unpack()``, from the block's arrays directly (no
    per-member concatenation)."""
    r, T = block.rows, len(block)
    members = block.members.tolist()
    cols: dict[str, pa.Array] = {
        "generation": pa.array(np.full(T, r.generation, np.int32)),
        "member": pa.array(np.repeat(block.members.astype(np.int32), block.lengths())),  # (T,)
        "episode": pa.array(np.asarray(r.episode, np.int32).reshape(T)),
        "step": pa.array(np.asarray(r.step, np.int32).reshape(T)),
    }
    for name in VECTOR_COLUMNS:
        a = np.asarray(getattr(r, name), dtype=np.float32)
        if a.ndim != 2 or a.shape[0] != T or a.shape[1] == 0:
            raise TrajectoryStoreError(
                f"cannot store members {members[0]}-{members[-1]} generation {r.generation}: column '{name}' "
                f"has shape {a.shape}, expected ({T}, width > 0) (does the env provide info "
                f"'position'/'waypoint'?)")
        cols[name] = _vector_column(a)  # (T, w)
    cols["reward"] = pa.array(np.asarray(r.reward, np.float32).reshape(T))
    names = list(COLUMNS)
    if r.expert is not None:
        cols[EXPERT] = _vector_column(np.asarray(r.expert, np.float32).reshape(T, -1))  # (T, act)
        names.append(EXPERT)
    meta = {FORMAT_KEY: FORMAT_VERSION, b"generation": str(r.generation).encode(),
            b"members": ",".join(map(str, members)).encode()}
    if run_id is not None:
        meta[RUN_KEY] = run_id
    return pa.table({c: cols[c] for c in names}).replace_schema_metadata(meta)


def _vector_column(a: np.ndarray) -> pa.Array:
    """``(T, w)`` float32 -> a ``fixed_size_binary[4 w]`` column of T values (one copy at most)."""
    a = np.ascontiguousarray(a, dtype="<f4")  # (T, w)
    return pa.FixedSizeBinaryArray.from_buffers(pa.binary(4 * a.shape[1]), a.shape[0], [None, pa.py_buffer(a)])


def _vector_values(col: pa.Array, name: str, bad) -> np.ndarray:
    """A vector column (format 2's ``fixed_size_binary[4 w]``, or format 1's ``fixed_size_list<float32>[w]``)
    -> ``(T, w)`` float32 (a view of the column's buffer where it can be)."""
    t = col.type
    if pa.types.is_fixed_size_binary(t) and t.byte_width % 4 == 0 and t.byte_width > 0:
        w = t.byte_width // 4
        flat = np.frombuffer(col.buffers()[1], dtype="<f4", count=(col.offset + len(col)) * w)
        return flat[col.offset * w :].reshape(len(col), w).astype(np.float32, copy=False)  # (T, w)
    if pa.types.is_fixed_size_list(t) and t.value_type == pa.float32():
        flat = col.flatten()  # (T*w,) respects slicing offsets
        if flat.null_count:
            raise bad(f"column '{name}' has null elements")
        return flat.to_numpy(zero_copy_only=False).reshape(len(col), t.list_size)  # (T, w)
    raise bad(f"column '{name}' has type {t}, expected fixed_size_binary (float32 vectors)")


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
        table = _packed_table(block, _owner(root))
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
        table = _to_table(trs, stacked, _owner(root))
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
        raise TrajectoryStoreError(f"corrupt trajectory shard {path}: {_first_line(exc).rstrip('.')}{_damaged_hint(path)}") \
            from None
    return _from_table(table, os.fspath(path))


def _from_table(table: pa.Table, where: str) -> list[Transitions]:
    def bad(why: str) -> TrajectoryStoreError:
        return TrajectoryStoreError(f"malformed trajectory shard {where}: {why}")

    meta = table.schema.metadata or {}
    if meta.get(FORMAT_KEY) not in READABLE_VERSIONS:
        raise bad(f"not a shaped-es trajectory shard (format {meta.get(FORMAT_KEY)!r})")
    owner = _owner(os.path.dirname(os.path.dirname(where.rstrip("/"))))  # ROOT of ROOT/gen_N/members_*
    if owner is not None and meta.get(RUN_KEY) != owner:
        theirs = meta.get(RUN_KEY)
        theirs = f"run {theirs.decode(errors='replace')}" if theirs else "no run (it has no run id)"
        raise TrajectoryStoreError(f"trajectory shard {where} belongs to {theirs}, not to run {owner.decode()} "
                                   f"whose directory holds it (copied from another run?)")
    try:
        generation = int(meta[b"generation"])
        members = [int(m) for m in meta[b"members"].decode().split(",")]
    except (KeyError, ValueError, UnicodeDecodeError):
        raise bad("schema metadata lacks generation/members") from None
    missing = [c for c in COLUMNS if c not in table.column_names]
    if missing:
        raise bad(f"missing columns {missing}")
    out: dict[str, np.ndarray] = {}
    optional = [EXPERT] if EXPERT in table.column_names else []
    for c in (*COLUMNS, *optional):
        col = table.column(c).combine_chunks()
        if col.null_count:
            raise bad(f"column '{c}' has nulls")
        if c in VECTOR_COLUMNS or c == EXPERT:
            out[c] = _vector_values(col, c, bad)  # (T, w)
        else:
            want = pa.float32() if c == "reward" else pa.int32()
            if col.type != want:
                raise bad(f"column '{c}' has type {col.type}, expected {want}")
            out[c] = col.to_numpy(zero_copy_only=False)
    if (out["generation"] != generation).any():
        raise bad("generation column disagrees with the shard's metadata")
    if out["position"].shape[1] != out["waypoint"].shape[1]:
        raise bad("position and waypoint widths differ")
    col_m = out["member"]
    if (np.diff(col_m) < 0).any() or not set(np.unique(col_m).tolist()) <= set(members) \
            or sorted(set(members)) != members:
        raise bad("member column disagrees with the shard's metadata")
    lo = np.searchsorted(col_m, members, side="left")  # (k,) first row of each member
    hi = np.searchsorted(col_m, members, side="right")
    if optional and out[EXPERT].shape[1] != out["action"].shape[1]:
        raise bad("expert and action widths differ")
    return [Transitions(generation=generation, member=m,
                        **{f: out[f][a:b] for f in ("episode", "step", "state", "position", "waypoint",
                                                   "action", "reward", *optional)})
            for m, a, b in zip(members, lo, hi)]


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
