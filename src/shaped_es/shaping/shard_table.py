"""A trajectory shard as an Arrow table: its columns, its format's metadata, and the two ways across, written
(:func:`to_table`, :func:`packed_table`) and read back with every check (:func:`from_table`). Where the shards
live, and how they are written and read as files, is the store's (``shaping/trajectories.py``).

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

The schema metadata holds the format version, the generation, the members and, for a shard written under a
``run_{id}`` directory, that run's id. A missing column, a wrong type, a null, metadata that disagrees with
the columns, or another run's id raises :class:`TrajectoryStoreError` (one line naming the file).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyarrow as pa

from shaped_es.data import COLUMNS, PackedTransitions, Transitions

INT_COLUMNS = ("generation", "member", "episode", "step")
VECTOR_COLUMNS = ("state", "position", "waypoint", "action")
EXPERT = "expert"  # optional vector column (data.Transitions.expert)
FORMAT_KEY, FORMAT_VERSION = b"shaped_es.trajectories", b"2"
READABLE_VERSIONS = (b"1", b"2")  # 1: vectors as fixed_size_list<float32>
RUN_KEY = b"run_id"


class TrajectoryStoreError(RuntimeError):
    """A trajectory shard is missing, corrupt or malformed, or cannot be written (message: one line)."""


def to_table(trs: Sequence[Transitions], stacked: Transitions | None = None,
             run_id: bytes | None = None) -> pa.Table:
    """One shard's table (schema above) of the members ``trs`` of one generation, in that order; ``stacked``:
    their rows already concatenated (used where its vector columns are float32), ``run_id``: the owning run's
    (the metadata's ``run_id``; None: none)."""
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


def packed_table(block: PackedTransitions, run_id: bytes | None = None) -> pa.Table:
    """The table :func:`to_table` makes of ``block.unpack()``, from the block's arrays directly (no
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


def from_table(table: pa.Table, where: str, owner: bytes | None) -> list[Transitions]:
    """Validate a shard's table and split it into one :class:`Transitions` per member, ascending (``where``: the
    shard's path, for the messages; ``owner``: the run id of the ``run_{id}`` directory that holds it, which the
    metadata's must match; None: not under one)."""
    def bad(why: str) -> TrajectoryStoreError:
        return TrajectoryStoreError(f"malformed trajectory shard {where}: {why}")

    meta = table.schema.metadata or {}
    if meta.get(FORMAT_KEY) not in READABLE_VERSIONS:
        raise bad(f"not a shaped-es trajectory shard (format {meta.get(FORMAT_KEY)!r})")
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
