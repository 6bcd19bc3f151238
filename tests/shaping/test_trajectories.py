"""Parquet trajectory store: exact round trip, layout, history reads, and clear errors on bad shards."""

from __future__ import annotations

import os

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from shaped_es.data import COLUMNS
from shaped_es.shaping.trajectories import (
    TrajectoryStoreError,
    TrajectoryStoreWarning,
    delete_generations,
    list_generations,
    read_generation,
    read_member_history,
    read_members,
    read_shard,
    run_root,
    write_shard,
)

FIELDS = ("episode", "step", "state", "position", "waypoint", "action", "reward")


def _assert_same(a, b):
    assert (a.generation, a.member) == (b.generation, b.member)
    for f in FIELDS:
        x, y = getattr(a, f), getattr(b, f)
        assert x.dtype == y.dtype and x.shape == y.shape, f
        np.testing.assert_array_equal(x, y, err_msg=f)


@pytest.fixture
def tr(make_transitions):
    rng = np.random.default_rng(0)
    return make_transitions(rng, episodes=3, steps=40, obs_dim=38, generation=3, member=7)


def test_roundtrip_is_exact_and_layout_as_documented(tr, tmp_path):
    path = write_shard(tmp_path / "trajectories", tr)
    assert path == str(tmp_path / "trajectories" / "gen_000003" / "members_0007-0007.parquet")
    assert os.listdir(os.path.dirname(path)) == ["members_0007-0007.parquet"]  # no temp file left behind
    (back,) = read_shard(path)
    _assert_same(tr, back)
    schema = pq.read_schema(path)
    assert schema.names == list(COLUMNS)
    assert schema.field("state").type == pa.binary(4 * 38)  # format 2: a row's 38 float32 as one value
    assert schema.metadata[b"shaped_es.trajectories"] == b"2"
    assert schema.field("step").type == pa.int32() and schema.field("reward").type == pa.float32()
    state = pq.read_table(path).column("state").combine_chunks()
    np.testing.assert_array_equal(np.frombuffer(state.buffers()[1], "<f4").reshape(-1, 38), tr.state)


def test_format_1_shards_with_list_columns_still_read(tr, tmp_path):
    """Shards written before format 2 (vectors as fixed_size_list<float32>) read the same."""
    table = pq.read_table(write_shard(tmp_path / "new", tr))
    for name in ("state", "position", "waypoint", "action"):
        a = getattr(tr, name)
        table = table.set_column(table.schema.get_field_index(name), name,
                                 pa.FixedSizeListArray.from_arrays(pa.array(a.reshape(-1)), a.shape[1]))
    meta = {**table.schema.metadata, b"shaped_es.trajectories": b"1"}
    old = tmp_path / "old" / "gen_000003" / "members_0007-0007.parquet"
    old.parent.mkdir(parents=True)
    pq.write_table(table.replace_schema_metadata(meta), old)
    _assert_same(tr, read_shard(old)[0])
    pq.write_table(table.replace_schema_metadata({**meta, b"shaped_es.trajectories": b"9"}), tmp_path / "v9.parquet")
    _expect_error(tmp_path / "v9.parquet", "not a shaped-es trajectory shard")


def test_roundtrip_through_a_filesystem_uri(tr, tmp_path):
    path = write_shard(f"file://{tmp_path}/store", tr)
    assert path == f"file://{tmp_path}/store/gen_000003/members_0007-0007.parquet"
    _assert_same(tr, read_shard(path)[0])
    assert list_generations(f"file://{tmp_path}/store") == [3]


def test_overwrite_replaces_and_empty_shard_roundtrips(tr, make_transitions, tmp_path):
    write_shard(tmp_path, tr)
    rng = np.random.default_rng(5)
    other = make_transitions(rng, episodes=1, steps=4, obs_dim=38, generation=3, member=7)
    _assert_same(other, read_shard(write_shard(tmp_path, other))[0])
    empty = make_transitions(rng, episodes=1, steps=0, obs_dim=38, generation=4, member=1)
    _assert_same(empty, read_shard(write_shard(tmp_path, empty))[0])


def test_generation_and_member_history_reads(make_transitions, tmp_path):
    rng = np.random.default_rng(1)
    written = {}
    for g in (0, 1, 2, 4):
        for m in (2, 0, 1):
            if (g, m) != (1, 1):  # member 1 has no shard in generation 1
                written[g, m] = make_transitions(rng, episodes=1, steps=5, generation=g, member=m)
                write_shard(tmp_path, written[g, m])
    (tmp_path / "gen_000002" / ".members_0003-0003.parquet.abc.tmp").write_bytes(b"partial")  # ignored
    assert list_generations(tmp_path) == [0, 1, 2, 4]
    gen2 = read_generation(tmp_path, 2)
    assert [t.member for t in gen2] == [0, 1, 2]
    for t in gen2:
        _assert_same(written[2, t.member], t)
    assert read_generation(tmp_path, 3) == []
    hist = read_member_history(tmp_path, 1, range(5))
    assert [t.generation for t in hist] == [0, 2, 4]
    hist = read_member_history(tmp_path, 0, range(5), last=2)  # the last 2 generations asked: 3 and 4
    assert [t.generation for t in hist] == [4]
    _assert_same(written[4, 0], hist[0])
    assert [t.generation for t in read_member_history(tmp_path, 0, [4, 1, 2], last=2)] == [2, 4]
    delete_generations(tmp_path, [0, 9])
    assert list_generations(tmp_path) == [1, 2, 4]
    # a file a user put in a generation's folder stays, and so does its folder; the shards and a killed
    # write's temporary go
    gen1 = tmp_path / "gen_000001"
    (gen1 / "mine.txt").write_text("mine")
    (gen1 / f".members_0000-0001.parquet.{'a' * 32}.tmp").write_bytes(b"half")
    delete_generations(tmp_path, [1, 2])
    assert sorted(p.name for p in gen1.iterdir()) == ["mine.txt"] and (gen1 / "mine.txt").read_text() == "mine"
    assert read_generation(tmp_path, 1) == [] and list_generations(tmp_path) == [1, 4]


def _expect_error(path, match):
    with pytest.raises(TrajectoryStoreError, match=match) as info:
        read_shard(path)
    msg = str(info.value)
    assert "\n" not in msg and str(path) in msg


def test_truncated_shard_raises(tr, tmp_path):
    path = write_shard(tmp_path, tr)
    data = open(path, "rb").read()
    for cut in (0, 10, len(data) // 2, len(data) - 3):
        with open(path, "wb") as fh:
            fh.write(data[:cut])
        _expect_error(path, "corrupt")


def test_flipped_data_byte_raises(tr, tmp_path):
    path = write_shard(tmp_path, tr)
    col = pq.ParquetFile(path).metadata.row_group(0).column(COLUMNS.index("state"))
    start = col.dictionary_page_offset or col.data_page_offset
    off = start + col.total_compressed_size // 2  # inside the state column chunk's pages
    data = bytearray(open(path, "rb").read())
    data[off] ^= 0xFF
    with open(path, "wb") as fh:
        fh.write(bytes(data))
    _expect_error(path, "corrupt")


def test_missing_or_foreign_or_malformed_shard_raises(tr, tmp_path):
    _expect_error(tmp_path / "nope.parquet", "not found")
    (tmp_path / "junk.parquet").write_bytes(b"not parquet at all")
    _expect_error(tmp_path / "junk.parquet", "corrupt")
    good = pq.read_table(write_shard(tmp_path, tr))
    pq.write_table(pa.table({"x": [1, 2]}), tmp_path / "foreign.parquet")
    _expect_error(tmp_path / "foreign.parquet", "not a shaped-es trajectory shard")
    pq.write_table(good.drop_columns(["reward"]), tmp_path / "missing.parquet")
    _expect_error(tmp_path / "missing.parquet", "missing columns")
    wide_step = good.set_column(3, "step", good.column("step").cast(pa.int64()))
    pq.write_table(wide_step, tmp_path / "type.parquet")
    _expect_error(tmp_path / "type.parquet", "'step' has type int64")
    as_float = good.set_column(4, "state", pa.array(np.zeros(good.num_rows, np.float32)))
    pq.write_table(as_float, tmp_path / "vector.parquet")
    _expect_error(tmp_path / "vector.parquet", "'state' has type float, expected fixed_size_binary")
    meta = {**good.schema.metadata, b"members": b"8"}
    pq.write_table(good.replace_schema_metadata(meta), tmp_path / "meta.parquet")
    _expect_error(tmp_path / "meta.parquet", "disagree")


def test_writing_transitions_without_positions_is_a_clear_error(make_transitions, tmp_path):
    tr = make_transitions(np.random.default_rng(0), pos_dim=2)
    tr.position, tr.waypoint = tr.position[:, :0], tr.waypoint[:, :0]
    with pytest.raises(TrajectoryStoreError, match="'position'"):
        write_shard(tmp_path, tr)
    assert not any(tmp_path.rglob("*.parquet"))


def test_one_shard_holds_many_members_and_reads_split_them(make_transitions, tmp_path):
    rng = np.random.default_rng(3)
    trs = {m: make_transitions(rng, episodes=2, steps=6 + m, generation=5, member=m) for m in (4, 2, 3)}
    trs[9] = make_transitions(rng, episodes=1, steps=0, generation=5, member=9)  # a member with no steps
    path = write_shard(tmp_path, list(trs.values()))
    assert path.endswith("gen_000005/members_0002-0009.parquet")
    from shaped_es.data import concat_members

    ordered = [trs[m] for m in (2, 3, 4, 9)]
    again = write_shard(tmp_path / "stacked", ordered, concat_members(ordered)[0])
    assert [t.member for t in read_shard(again)] == [2, 3, 4, 9]
    for a, b in zip(read_shard(again), ordered):
        _assert_same(b, a)
    back = read_shard(path)
    assert [t.member for t in back] == [2, 3, 4, 9]
    for t in back:
        _assert_same(trs[t.member], t)
    write_shard(tmp_path, make_transitions(rng, episodes=1, steps=3, generation=5, member=10))
    assert [t.member for t in read_generation(tmp_path, 5)] == [2, 3, 4, 9, 10]
    got = read_members(tmp_path, [3, 10, 11], [5, 6])
    assert [len(got[m]) for m in (3, 10, 11)] == [1, 1, 0]
    _assert_same(trs[3], got[3][0])
    with pytest.raises(TrajectoryStoreError, match="distinct members of one generation"):
        write_shard(tmp_path, [trs[2], trs[2]])


def test_each_run_under_a_shared_root_has_its_own_directory_and_shards_know_their_run(tr, tmp_path):
    shared = str(tmp_path / "shared")
    own = str(tmp_path / "run" / "trajectories")
    assert run_root(None, own, "ab" * 8) == own  # the default root is the run's own
    a, b = run_root(shared, "unused", "a" * 16), run_root(shared, "unused", "b" * 16)
    assert a == os.path.join(shared, "run_" + "a" * 16) and a != b
    assert run_root(f"file://{shared}", "unused", "a" * 16) == f"file://{shared}/run_{'a' * 16}"
    path = write_shard(a, tr)
    assert pq.read_schema(path).metadata[b"run_id"] == b"a" * 16
    _assert_same(tr, read_generation(a, 3)[0])
    os.makedirs(os.path.join(b, "gen_000003"))
    os.replace(path, os.path.join(b, "gen_000003", os.path.basename(path)))  # a shard moved to another run
    with pytest.raises(TrajectoryStoreError, match=f"belongs to run {'a' * 16}, not to run {'b' * 16}"):
        read_generation(b, 3)
    legacy = write_shard(str(tmp_path / "plain"), tr)  # no run_<id> directory: no id, nothing to check
    assert b"run_id" not in pq.read_schema(legacy).metadata and read_shard(legacy)


def test_a_run_without_an_id_keeps_the_shared_root_with_a_warning(tmp_path):
    with pytest.warns(TrajectoryStoreWarning, match="not kept apart from other runs"):
        assert run_root(str(tmp_path), "unused", None) == str(tmp_path)
