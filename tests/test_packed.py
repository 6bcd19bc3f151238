"""Packed transitions (data.PackedTransitions): one block per rollout task, equal to the per-member
Transitions the rollouts made before, field by field."""

import dataclasses

import numpy as np
import pytest

from shaped_es.data import (
    PackedTransitions,
    Transitions,
    concat_members,
    join_packed,
    pack,
)
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask, _Recorder, run_task
from shaped_es.shaping.shard_table import packed_table, to_table
from shaped_es.shaping.trajectories import read_shard, write_shard

FIELDS = [f.name for f in dataclasses.fields(Transitions)]


def _same(a: Transitions, b: Transitions) -> None:
    for f in FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            assert x is not None and y is not None, f
            assert x.dtype == y.dtype and x.shape == y.shape, f
            np.testing.assert_array_equal(x, y, err_msg=f)
        else:
            assert x == y, f


def _per_member_build(rec: _Recorder) -> list[Transitions]:
    """The recorder's result as it was built before packing (per episode concatenates): the reference."""
    E = rec.task.seeds.shape[1]
    obs, pos, wp, act, rew, alive, *ex = (b[: rec.t] for b in rec.buf)  # (T, B_r, ...)
    lens = alive.sum(axis=0)
    out = []
    for j, r in enumerate(rec.rows):
        bs = range(j * E, j * E + E)
        def cat(x, bs=bs):
            return np.concatenate([x[: lens[b], b] for b in bs])

        out.append(Transitions(
            generation=rec.task.generation, member=int(rec.task.members[r]),
            episode=np.concatenate([np.full(lens[b], e, np.int32) for e, b in enumerate(bs)]),
            step=np.concatenate([np.arange(lens[b], dtype=np.int32) for b in bs]),
            state=cat(obs), position=cat(pos), waypoint=cat(wp), action=cat(act), reward=cat(rew),
            expert=cat(ex[0]) if ex else None))
    return out


def _fixed_recorder(mask, E=3, T=7, expert=True, seed=0) -> _Recorder:
    """A recorder fed fixed random steps of ``len(mask)`` members x E episodes of ragged lengths."""
    rng = np.random.default_rng(seed)
    m = len(mask)
    task = RolloutTask("x", {}, MLPSpec(5, 2, (4,)), np.zeros((m, 1), np.float32), np.arange(10, 10 + m),
                       np.zeros((m, E), np.int64), generation=4, record=np.asarray(mask))
    rec = _Recorder(task, capacity=2)  # grows while recording
    B = m * E
    lens = rng.integers(1, T + 1, size=B)  # (B,) each episode's steps
    for t in range(T):
        alive = t < lens
        rec.add(rng.standard_normal((B, 5)), rng.standard_normal((B, 2)), rng.standard_normal((B, 2)),
                rng.standard_normal((B, 2)).astype(np.float32), np.where(alive, rng.standard_normal(B), 0.0),
                alive, rng.standard_normal((B, 2)) if expert else None)
    return rec


@pytest.mark.parametrize("mask", [[True] * 4, [True, False, True, True], [False, True, False, False]])
@pytest.mark.parametrize("expert", [True, False])
def test_recorder_block_equals_the_per_member_build(mask, expert):
    rec = _fixed_recorder(mask, expert=expert)
    block = rec.build()
    ref = _per_member_build(rec)
    assert block.members.tolist() == [t.member for t in ref]
    got = block.unpack()
    assert len(got) == len(ref)
    for a, b in zip(got, ref):
        _same(a, b)
    # the generation stacked: what data.concat_members gives of the per-member list
    big, offsets = concat_members(ref)
    _same(block.stacked(), big)
    np.testing.assert_array_equal(block.offsets, offsets)


def test_pack_unpack_round_trip_and_join():
    rec = _fixed_recorder([True] * 5, seed=1)
    ref = _per_member_build(rec)
    for a, b in zip(pack(ref).unpack(), ref):
        _same(a, b)
    # blocks of consecutive members (one per task), given in any order, join into the whole
    parts = [pack(ref[:2]), pack(ref[2:3]), pack(ref[3:])]
    whole = join_packed(parts[::-1])
    for a, b in zip(whole.unpack(), ref):
        _same(a, b)
    np.testing.assert_array_equal(whole.offsets, pack(ref).offsets)
    with pytest.raises(ValueError):
        join_packed([pack(ref[:3]), pack(ref[2:])])  # member 2 twice


def test_nonempty_drops_members_without_rows():
    rec = _fixed_recorder([True] * 3, seed=2)
    ref = _per_member_build(rec)
    empty = dataclasses.replace(ref[1], **{f: getattr(ref[1], f)[:0] for f in FIELDS[2:]})
    block = pack([ref[0], empty, ref[2]]).nonempty()
    assert block.members.tolist() == [ref[0].member, ref[2].member]
    for a, b in zip(block.unpack(), [ref[0], ref[2]]):
        _same(a, b)


def test_a_block_writes_the_shard_the_member_list_writes(tmp_path):
    ref = _per_member_build(_fixed_recorder([True] * 4, seed=3))
    block = pack(ref)
    assert packed_table(block).equals(to_table(ref))
    assert packed_table(block).schema.metadata == to_table(ref).schema.metadata
    a = read_shard(write_shard(tmp_path / "list", ref))
    b = read_shard(write_shard(tmp_path / "block", block))
    for x, y in zip(a, b):
        _same(x, y)


def test_a_rollout_result_crosses_as_one_block():
    spec = MLPSpec(13, 5, (8,))
    P = np.stack([spec.init(i) for i in range(3)])
    res = run_task(RolloutTask("shaped_es:UR5Reach-v0", {}, spec, P, np.arange(3), np.array([[1, 2]] * 3),
                               record=np.array([True, False, True]), max_steps=20))
    assert isinstance(res.packed, PackedTransitions) and res.packed.members.tolist() == [0, 2]
    assert [t.member for t in res.transitions] == [0, 2]
    assert "transitions" not in vars(res)  # pickled as the block only
    for t, row in zip(res.transitions, (0, 2)):
        np.testing.assert_allclose(t.episode_returns(), res.returns[row], rtol=1e-5)
