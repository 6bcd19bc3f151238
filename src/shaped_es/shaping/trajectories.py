"""The trajectory store: the paper's shared NFS, onto which every worker writes its rollouts (Sec. IV).

One Parquet shard per (generation, member)::

    ROOT/gen_{g:06d}/member_{m:04d}.parquet        (ROOT = RUN/trajectories by convention)

========================================  ========================================================
column                                    type
========================================  ========================================================
``generation``, ``member``                int32 (constant in a shard; also in the schema metadata)
``episode``, ``step``                     int32
``state``                                 fixed_size_list<float32>[obs_dim]
``position``, ``waypoint``                fixed_size_list<float32>[d]
``action``                                fixed_size_list<float32>[act_dim]
``reward``                                float32
========================================  ========================================================

``ROOT`` is a local path or any URI ``pyarrow.fs.FileSystem.from_uri`` understands (``file://``,
``s3://``, ...). Writes are atomic: a temporary file in the same directory, then a rename, so a reader
sees a complete shard or none. Shards carry page checksums; a missing column, a wrong type, a null or a
checksum mismatch on read raises :class:`TrajectoryStoreError` (one line naming the file). Never pickle.

The master reads a whole generation to train ``M_phi``; worker ``i`` reads its own history ``D_i``
(DAgger-style aggregation over generations, Algorithm 1) with :func:`read_member_history`.
"""

from __future__ import annotations

import os
import re
import uuid
from collections.abc import Iterable

import numpy as np
import pyarrow as pa
import pyarrow.fs as pafs
import pyarrow.parquet as pq

from shaped_es.data import COLUMNS, Transitions

INT_COLUMNS = ("generation", "member", "episode", "step")
VECTOR_COLUMNS = ("state", "position", "waypoint", "action")
FORMAT_KEY, FORMAT_VERSION = b"shaped_es.trajectories", b"1"
_MEMBER_RE = re.compile(r"^member_(\d{4,})\.parquet$")
_GEN_RE = re.compile(r"^gen_(\d{6,})$")


class TrajectoryStoreError(RuntimeError):
    """A trajectory shard is missing, corrupt or malformed, or cannot be written (message: one line)."""


def _resolve(where: str | os.PathLike) -> tuple[pafs.FileSystem, str]:
    s = os.fspath(where)
    if "://" in s:
        fs, path = pafs.FileSystem.from_uri(s)
        return fs, path.rstrip("/")
    return pafs.LocalFileSystem(), os.path.abspath(s)


def _join(root: str | os.PathLike, *parts: str) -> str:
    s = os.fspath(root)
    return "/".join([s.rstrip("/"), *parts]) if "://" in s else os.path.join(s, *parts)


def shard_path(root: str | os.PathLike, generation: int, member: int) -> str:
    """``ROOT/gen_{g:06d}/member_{m:04d}.parquet`` (a URI when ``root`` is one)."""
    return _join(root, f"gen_{generation:06d}", f"member_{member:04d}.parquet")


def _to_table(tr: Transitions) -> pa.Table:
    T = len(tr)
    cols: dict[str, pa.Array] = {
        "generation": pa.array(np.full(T, tr.generation, np.int32)),
        "member": pa.array(np.full(T, tr.member, np.int32)),
        "episode": pa.array(np.asarray(tr.episode, np.int32).reshape(T)),
        "step": pa.array(np.asarray(tr.step, np.int32).reshape(T)),
    }
    for name in VECTOR_COLUMNS:
        a = np.ascontiguousarray(getattr(tr, name), dtype=np.float32)
        if a.ndim != 2 or a.shape[0] != T or a.shape[1] == 0:
            raise TrajectoryStoreError(
                f"cannot store member {tr.member} generation {tr.generation}: column '{name}' has shape "
                f"{a.shape}, expected ({T}, width > 0) (does the env provide info 'position'/'waypoint'?)"
            )
        flat = pa.array(a.reshape(-1))  # (T, w) -> (T*w,)
        cols[name] = pa.FixedSizeListArray.from_arrays(flat, a.shape[1])  # T lists of w
    cols["reward"] = pa.array(np.asarray(tr.reward, np.float32).reshape(T))
    meta = {FORMAT_KEY: FORMAT_VERSION, b"generation": str(tr.generation).encode(),
            b"member": str(tr.member).encode()}
    return pa.table({c: cols[c] for c in COLUMNS}).replace_schema_metadata(meta)


def write_shard(root: str | os.PathLike, transitions: Transitions) -> str:
    """Write one member's transitions of one generation atomically; returns the shard's path."""
    table = _to_table(transitions)
    dest = shard_path(root, transitions.generation, transitions.member)
    fs, path = _resolve(dest)
    parent, name = path.rsplit("/", 1) if not isinstance(fs, pafs.LocalFileSystem) else os.path.split(path)
    tmp = f"{parent}/.{name}.{uuid.uuid4().hex}.tmp"
    opts = dict(compression="zstd", write_page_checksum=True)
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


def read_shard(path: str | os.PathLike) -> Transitions:
    """Read and validate one shard (see the module docstring for the schema)."""
    fs, p = _resolve(path)
    try:
        table = pq.read_table(p, filesystem=fs, page_checksum_verification=True)
    except FileNotFoundError:
        raise TrajectoryStoreError(f"trajectory shard not found: {path}") from None
    except (OSError, pa.ArrowException, ValueError) as exc:
        raise TrajectoryStoreError(f"corrupt trajectory shard {path}: {_first_line(exc)}") from None
    return _from_table(table, os.fspath(path))


def _from_table(table: pa.Table, where: str) -> Transitions:
    def bad(why: str) -> TrajectoryStoreError:
        return TrajectoryStoreError(f"malformed trajectory shard {where}: {why}")

    meta = table.schema.metadata or {}
    if meta.get(FORMAT_KEY) != FORMAT_VERSION:
        raise bad(f"not a shaped-es trajectory shard (format {meta.get(FORMAT_KEY)!r})")
    try:
        generation, member = int(meta[b"generation"]), int(meta[b"member"])
    except (KeyError, ValueError):
        raise bad("schema metadata lacks generation/member") from None
    missing = [c for c in COLUMNS if c not in table.column_names]
    if missing:
        raise bad(f"missing columns {missing}")
    out: dict[str, np.ndarray] = {}
    for c in COLUMNS:
        col = table.column(c).combine_chunks()
        if col.null_count:
            raise bad(f"column '{c}' has nulls")
        if c in VECTOR_COLUMNS:
            t = col.type
            if not (pa.types.is_fixed_size_list(t) and t.value_type == pa.float32()):
                raise bad(f"column '{c}' has type {t}, expected fixed_size_list<float32>")
            flat = col.flatten()  # (T*w,) respects slicing offsets
            if flat.null_count:
                raise bad(f"column '{c}' has null elements")
            out[c] = flat.to_numpy(zero_copy_only=False).reshape(len(col), t.list_size)  # (T, w)
        else:
            want = pa.float32() if c == "reward" else pa.int32()
            if col.type != want:
                raise bad(f"column '{c}' has type {col.type}, expected {want}")
            out[c] = col.to_numpy(zero_copy_only=False)
    if (out["generation"] != generation).any() or (out["member"] != member).any():
        raise bad("generation/member columns disagree with the shard's metadata")
    if out["position"].shape[1] != out["waypoint"].shape[1]:
        raise bad("position and waypoint widths differ")
    return Transitions(generation=generation, member=member, episode=out["episode"], step=out["step"],
                       state=out["state"], position=out["position"], waypoint=out["waypoint"],
                       action=out["action"], reward=out["reward"])


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


def read_generation(root: str | os.PathLike, generation: int) -> list[Transitions]:
    """Every member's shard of one generation, by member index (``[]`` if the generation has none)."""
    gen_dir = _join(root, f"gen_{generation:06d}")
    fs, p = _resolve(gen_dir)
    found = [(_MEMBER_RE.match(i.base_name), i) for i in _listdir(fs, p) if i.type == pafs.FileType.File]
    members = sorted(int(m.group(1)) for m, _ in found if m)
    return [read_shard(shard_path(root, generation, m)) for m in members]


def read_member_history(
    root: str | os.PathLike, member: int, generations: Iterable[int], last: int | None = None
) -> list[Transitions]:
    """Member ``i``'s aggregated data set ``D_i`` (DAgger-style): its shards of ``generations``, oldest
    first, restricted to the ``last`` newest of them when given. Generations without a shard for this
    member are skipped (e.g. before the shaped phase started)."""
    gens = sorted(set(int(g) for g in generations))
    if last is not None:
        gens = gens[-last:] if last > 0 else []
    out = []
    for g in gens:
        path = shard_path(root, g, member)
        fs, p = _resolve(path)
        if fs.get_file_info(p).type == pafs.FileType.File:
            out.append(read_shard(path))
    return out


def delete_generations(root: str | os.PathLike, generations: Iterable[int]) -> None:
    """Remove whole generations from the store (disk budget, or shards a killed run wrote past its
    last checkpoint). Missing generations are ignored."""
    for g in generations:
        fs, p = _resolve(_join(root, f"gen_{int(g):06d}"))
        if fs.get_file_info(p).type == pafs.FileType.Directory:
            fs.delete_dir(p)
