import json

import numpy as np
import pytest

from shaped_es.config import ConfigError, build_config
from shaped_es.rundir.store import RunStore, StoreError


def test_store_checkpoint_and_metrics(tmp_path):
    store = RunStore(tmp_path / "run")
    cfg = build_config({"env": "CartPole-v1"})
    store.create(cfg)
    with pytest.raises(StoreError, match="holds a run that finished no generation .its start failed.: 'shaped-es "
                                         "resume"):
        store.create(cfg)
    assert store.read_config() == cfg
    for g in range(4):
        store.append_metrics({"generation": g, "x": g * 0.5})
    with pytest.raises(StoreError, match="already holds a run"):
        store.create(cfg)
    store.truncate_metrics(1)
    assert [r["generation"] for r in store.read_metrics()] == ["0", "1"]
    with pytest.raises(StoreError):
        store.append_metrics({"generation": 2, "x": 1, "new": 3})
    for g in (1, 2, 3, 4):
        store.save_checkpoint(g, {"a": np.full(3, g)}, {"k": g}, keep=2)
    arrays, meta = store.load_checkpoint()
    assert meta["generation"] == 4 and (arrays["a"] == 4).all()
    assert len(list(store.ckpt_dir.glob("gen_*.npz"))) == 2


def test_keeping_the_newest_checkpoints_deletes_only_the_runs_own(tmp_path):
    """A new user's backup copy beside the checkpoints (gen_000002_backup.npz / .json) matched the old
    gen_*.npz pruning and was deleted with the run's own older checkpoints: only gen_NNNNNN files go now."""
    store = RunStore(tmp_path)
    store.save_checkpoint(1, {"a": np.zeros(2)}, {}, keep=2)
    store.save_checkpoint(2, {"a": np.ones(2)}, {}, keep=2)
    for ext in ("npz", "json"):
        (store.ckpt_dir / f"gen_000002_backup.{ext}").write_bytes((store.ckpt_dir / f"gen_000002.{ext}").read_bytes())
    (store.ckpt_dir / "gen_old.npz").write_bytes(b"mine")
    for g in (3, 4, 5):
        store.save_checkpoint(g, {"a": np.full(2, g)}, {}, keep=2)
    names = sorted(p.name for p in store.ckpt_dir.iterdir())
    assert names == ["gen_000002_backup.json", "gen_000002_backup.npz", "gen_000004.json", "gen_000004.npz",
                     "gen_000005.json", "gen_000005.npz", "gen_old.npz", "latest.json"]
    assert store.checkpoints() == [4, 5]


def test_store_rejects_bad_checkpoints(tmp_path):
    store = RunStore(tmp_path)
    store.save_checkpoint(1, {"a": np.zeros(2)}, {}, keep=3)
    # an object array would need pickle to load: refused
    np.save(tmp_path / "x.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    obj = store.ckpt_dir / "gen_000001.npz"
    import zipfile

    with zipfile.ZipFile(obj, "w") as z:
        z.write(tmp_path / "x.npy", "a.npy")
    with pytest.raises(StoreError, match="unreadable"):
        store.load_checkpoint()
    (store.ckpt_dir / "gen_000001.npz").write_bytes(b"garbage")
    with pytest.raises(StoreError, match="unreadable"):
        store.load_checkpoint()
    (store.ckpt_dir / "latest.json").write_text(json.dumps({"nope": 1}))
    with pytest.raises(StoreError):
        store.load_checkpoint()


def test_a_run_gets_an_id_once_and_a_damaged_one_is_refused(tmp_path):
    store = RunStore(tmp_path / "run")
    assert store.run_id() is None  # no run (or one made before runs had ids)
    store.create(build_config({"env": "CartPole-v1"}))
    rid = store.run_id()
    assert len(rid) == 16 and int(rid, 16) >= 0
    assert RunStore(tmp_path / "run").run_id() == rid  # kept: read, never rewritten
    other = RunStore(tmp_path / "other")
    other.create(build_config({"env": "CartPole-v1"}))
    assert other.run_id() != rid
    store.run_json.write_text('{"run_id": "../../x"}')
    with pytest.raises(StoreError, match="holds no run id"):
        store.run_id()


def test_save_config_writes_only_a_change(tmp_path):
    store = RunStore(tmp_path / "run")
    cfg = build_config({"env": "CartPole-v1"})
    store.create(cfg)
    store.config_path.write_text(store.config_path.read_text() + "\n# a comment the user wrote\n")
    before = store.config_path.read_bytes()
    store.save_config(cfg)
    assert store.config_path.read_bytes() == before  # the same config: untouched
    store.save_config(build_config({"env": "CartPole-v1", "generations": 60}))
    assert store.read_config().generations == 60


def test_a_run_saved_before_test_policy_existed_reads_as_the_rule_it_ran_under(tmp_path):
    # every saved config.yaml lists every field: one without rollout.test_policy tested the best member
    store = RunStore(tmp_path / "run")
    store.create(build_config({"env": "CartPole-v1"}))
    assert store.read_config().rollout.test_policy == "mean"  # today's default, as written
    text = store.config_path.read_text()
    assert "  test_policy: mean\n" in text
    store.config_path.write_text(text.replace("  test_policy: mean\n", ""))
    assert store.read_config().rollout.test_policy == "best"
    store.config_path.write_text("- a list, not a config\n")
    with pytest.raises(ConfigError, match="must hold a mapping"):  # its one-line error, not a traceback
        store.read_config()
