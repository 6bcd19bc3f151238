import json

import numpy as np
import pytest

from shaped_es.policies import MLPSpec
from shaped_es.rollout import EnvSpecError, RolloutTask, make_env, run_task
from shaped_es.store import RunStore, StoreError
from shaped_es.config import build_config


def _task(record=False, seeds=((1, 2), (1, 2), (3, 4))):
    spec = MLPSpec(4, 2, (8,))
    P = np.stack([spec.init(i) for i in range(len(seeds))])
    return RolloutTask("CartPole-v1", {}, spec, P, np.arange(len(seeds)), np.array(seeds), record=record)


def test_rollout_deterministic_and_chunk_independent():
    full = run_task(_task())
    again = run_task(_task())
    np.testing.assert_array_equal(full.returns, again.returns)
    # member 0 alone gives the same returns as inside the chunk
    t = _task()
    t.params, t.members, t.seeds = t.params[:1], t.members[:1], t.seeds[:1]
    np.testing.assert_array_equal(run_task(t).returns[0], full.returns[0])
    # CartPole pays +1 per step: returns equal lengths
    np.testing.assert_array_equal(full.returns, full.lengths)


def test_rollout_records_transitions():
    res = run_task(_task(record=True))
    assert len(res.transitions) == 3
    tr = res.transitions[1]
    assert len(tr) == res.lengths[1].sum()
    np.testing.assert_allclose(tr.episode_returns(), res.returns[1])
    assert tr.state.shape == (len(tr), 4) and tr.action.shape == (len(tr), 2)
    assert tr.position.shape == (len(tr), 0)  # CartPole does not carry the waypoint contract


def test_unknown_env_one_line():
    for bad in ("NoSuchEnv-v0", "no_such_module:Foo-v0"):
        with pytest.raises(EnvSpecError) as e:
            make_env(bad)
        assert "\n" not in str(e.value)


def test_store_checkpoint_and_metrics(tmp_path):
    store = RunStore(tmp_path / "run")
    cfg = build_config({"env": "CartPole-v1"})
    store.create(cfg)
    with pytest.raises(StoreError, match="already holds a run"):
        store.create(cfg)
    assert store.read_config() == cfg
    for g in range(4):
        store.append_metrics({"generation": g, "x": g * 0.5})
    store.truncate_metrics(1)
    assert [r["generation"] for r in store.read_metrics()] == ["0", "1"]
    with pytest.raises(StoreError):
        store.append_metrics({"generation": 2, "x": 1, "new": 3})
    for g in (1, 2, 3, 4):
        store.save_checkpoint(g, {"a": np.full(3, g)}, {"k": g}, keep=2)
    arrays, meta = store.load_checkpoint()
    assert meta["generation"] == 4 and (arrays["a"] == 4).all()
    assert len(list(store.ckpt_dir.glob("gen_*.npz"))) == 2


def test_store_rejects_bad_checkpoints(tmp_path):
    store = RunStore(tmp_path)
    store.save_checkpoint(1, {"a": np.zeros(2)}, {}, keep=3)
    # an object array would need pickle to load: refused
    np.save(tmp_path / "x.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    obj = store.ckpt_dir / "gen_000001.npz"
    import io
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
