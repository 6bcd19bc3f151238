"""What ``RunStore.recover`` makes of every state a killed writer can leave, file by file (no processes):
temporaries, a ``.npz`` without its ``.json``, a ``.json`` whose ``.npz`` was pruned, a stale or missing
``latest.json``, a torn last metrics row, rows past the checkpoint."""

from __future__ import annotations

import json

import numpy as np
import pytest

from shaped_es.rundir.store import RunStore, StoreError


def _store(tmp_path, gens=(1, 2, 3), rows=5) -> RunStore:
    store = RunStore(tmp_path / "run")
    store.root.mkdir()
    for g in gens:
        store.save_checkpoint(g, {"a": np.full(2, g)}, {"k": g}, keep=3)
    for g in range(rows):
        store.append_metrics({"generation": g, "x": g / 2})
    return store


def test_recover_cleans_what_a_kill_leaves(tmp_path):
    store = _store(tmp_path)
    ck = store.ckpt_dir
    (ck / ".gen_000004.npz.abc.tmp").write_bytes(b"half")  # killed before the rename
    (store.root / ".metrics.csv.x.tmp").write_text("x")
    (store.root / "mphi_data").mkdir()
    (store.root / "mphi_data" / ".added_000004.npz.y.tmp").write_bytes(b"")
    (ck / "gen_000004.npz").write_bytes(b"a complete npz without its json")  # killed before the json
    (ck / "gen_000000.json").write_text("{}")  # pruning killed between the npz and the json
    (ck / "latest.json").write_text(json.dumps({"name": "gen_000002"}))  # killed before latest.json
    with store.metrics_path.open("a") as fh:
        fh.write("5,2.")  # a torn row
    assert [int(r["generation"]) for r in store.read_metrics()] == [0, 1, 2, 3, 4]  # torn row left out
    with store.lock():
        arrays, meta = store.recover()
    assert meta["generation"] == 3 and (arrays["a"] == 3).all()
    assert sorted(p.name for p in ck.iterdir()) == [f"gen_00000{g}.{e}" for g in (1, 2, 3)
                                                    for e in ("json", "npz")] + ["latest.json"]
    assert json.loads((ck / "latest.json").read_text())["name"] == "gen_000003"
    assert not list(store.root.rglob("*.tmp"))
    assert [int(r["generation"]) for r in store.read_metrics()] == [0, 1, 2]  # rows the checkpoint covers
    assert store.metrics_path.read_bytes().endswith(b"\r\n")


def test_recover_without_a_checkpoint_drops_every_row(tmp_path):
    store = _store(tmp_path, gens=(), rows=2)
    with store.lock():
        assert store.recover() is None
    assert store.read_metrics() == [] and store.metrics_path.read_text().startswith("generation")


def test_waiting_rows_are_written_again(tmp_path):
    store = RunStore(tmp_path / "run")
    store.root.mkdir()
    store.save_checkpoint(4, {"a": np.zeros(1)}, {"waiting_rows": [{"generation": 3}]}, keep=3)
    for g in range(5):
        store.append_metrics({"generation": g})
    with store.lock():
        store.recover()
    assert [int(r["generation"]) for r in store.read_metrics()] == [0, 1, 2]


def test_a_damaged_newest_checkpoint_is_an_error_not_a_silent_fallback(tmp_path):
    store = _store(tmp_path)
    (store.ckpt_dir / "gen_000003.npz").write_bytes(b"")
    before = store.metrics_path.read_bytes()
    with store.lock(), pytest.raises(StoreError, match="gen_000003.*move gen_000003.npz, gen_000003.json "
                                                       "and latest.json out of .* to resume from gen_000002"):
        store.recover()
    assert store.metrics_path.read_bytes() == before  # nothing changed
    aside = tmp_path / "aside"
    aside.mkdir()
    for name in ("gen_000003.npz", "gen_000003.json", "latest.json"):  # the line's advice, followed
        (store.ckpt_dir / name).rename(aside / name)
    with store.lock():
        store.recover()
    assert store.load_checkpoint()[1]["generation"] == 2


def test_repeated_rows_of_two_writers_keep_the_last_of_each_generation(tmp_path):
    store = _store(tmp_path, gens=(3,), rows=0)
    # a second writer resumed from generation 1 while the first went on
    for g, x in [(0, 0), (1, 1), (2, 2), (1, 11), (2, 12), (3, 13), (2, 22)]:
        store.append_metrics({"generation": g, "x": x})
    with pytest.raises(StoreError, match="does not follow"):
        store.read_metrics()
    with store.lock(), pytest.warns(UserWarning, match="held 3 repeated rows"):
        store.recover()
    rows = store.read_metrics()
    assert [int(r["generation"]) for r in rows] == [0, 1, 2]
    assert [int(r["x"]) for r in rows] == [0, 11, 22]  # the last written of each


@pytest.mark.parametrize("damage", ["deleted", "cut"])
def test_rows_the_checkpoint_covers_must_be_there_and_nothing_changes_if_not(tmp_path, damage):
    store = _store(tmp_path, gens=(3,), rows=3)
    (store.ckpt_dir / ".gen_000004.npz.x.tmp").write_bytes(b"half")
    if damage == "deleted":
        store.metrics_path.unlink()
    else:
        lines = store.metrics_path.read_text().splitlines(keepends=True)
        store.metrics_path.write_text("".join(lines[:2]))  # header and generation 0
    before = {p: p.read_bytes() for p in store.root.rglob("*") if p.is_file()}
    what = "is missing" if damage == "deleted" else "lacks the rows of generations 1-2"
    covers = "\\(checkpoint gen_000003 covers generations 0-2\\)"
    with store.lock(), pytest.raises(StoreError, match=f"{what} {covers}"):
        store.recover()
    assert {p: p.read_bytes() for p in store.root.rglob("*") if p.is_file()} == before


def test_rows_past_the_first_checkpoint_without_any_checkpoint_are_an_error(tmp_path):
    """Checkpoints deleted by hand: going on would start at generation 0 and drop every row. A run
    killed before its first checkpoint (rows of the first interval only) still recovers."""
    store = _store(tmp_path, gens=(), rows=0)
    for g in range(4):
        store.append_metrics({"generation": g})
    before = store.metrics_path.read_bytes()
    with store.lock(), pytest.raises(StoreError, match="holds no checkpoint, but .* generations 0-3 .* every 2 gen"):
        store.prepare_recovery(uncheckpointed=2)
    assert store.metrics_path.read_bytes() == before  # nothing changed
    with store.lock():
        store.prepare_recovery(uncheckpointed=4)[1]()  # the first 4 rows may precede a first checkpoint at 4
    assert store.metrics_path.read_bytes() != before  # the rows no checkpoint covers are dropped, as before
