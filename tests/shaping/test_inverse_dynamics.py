"""Inverse-dynamics model M_phi: recovery of a known model, filtering, determinism, state, threads (its
inputs, training pairs and queries: test_mphi_inputs.py)."""

from __future__ import annotations

import threading

import numpy as np
import pytest
from safetensors.numpy import load_file, save_file

from shaped_es.shaping.inverse_dynamics import InverseDynamics, InverseDynamicsConfig
from shaped_es.shaping.mphi_inputs import query_displacement, training_pairs

B = np.array([[0.5, 0.2], [-0.1, 0.4]])  # position_{t+1} - position_t = B a_t


def _data(make_transitions, seed=0, members=10, steps=100):
    rng = np.random.default_rng(seed)
    return [make_transitions(rng, episodes=2, steps=steps, B=B, member=m) for m in range(members)]


def test_recovers_known_linear_inverse_model(make_transitions):
    model = InverseDynamics(4, 2, 2, InverseDynamicsConfig(seed=1))
    model.add(_data(make_transitions))
    losses = model.train(1500)
    assert len(losses) == 1500 and model.iterations == 1500
    assert np.mean(losses[-100:]) < 0.1 * np.mean(losses[:100])
    rng = np.random.default_rng(99)
    a = rng.uniform(-0.8, 0.8, size=(500, 2)).astype(np.float32)  # (N, act)
    s = rng.normal(size=(500, 4)).astype(np.float32)  # (N, obs)
    err = np.abs(model.label(s, a @ B.T) - a)
    assert err.mean() < 0.04
    assert model.test_loss(s, a @ B.T, a) < 0.06


def test_min_return_filter_keeps_good_episodes(make_transitions):
    rng = np.random.default_rng(0)
    trs = [make_transitions(rng, episodes=4, steps=10, returns=[10.0, 2.0, 6.0, -1.0]),
           make_transitions(rng, episodes=2, steps=10, returns=[4.9, 5.0])]
    model = InverseDynamics(4, 2, 2, InverseDynamicsConfig(min_return=5.0, filter="total"))
    stats = model.add(trs)
    assert stats["episodes"] == 6 and stats["kept_episodes"] == 3
    assert stats["kept_fraction"] == pytest.approx(0.5)
    assert stats["dataset_size"] == 3 * 9  # 9 steps with a successor per kept episode
    bad = InverseDynamics(4, 2, 2, InverseDynamicsConfig(min_return=100.0, filter="total"))
    assert bad.add(trs)["dataset_size"] == 0 and bad.train(10) == []
    every = InverseDynamics(4, 2, 2, InverseDynamicsConfig(min_return=100.0))  # the default keeps all
    assert every.add(trs)["dataset_size"] == 6 * 9


def test_dataset_is_capped_fifo(make_transitions):
    trs = _data(make_transitions, members=3, steps=20)  # 3 * 2 * 19 = 114 rows
    model = InverseDynamics(4, 2, 2, InverseDynamicsConfig(max_dataset=50))
    assert model.add(trs)["dataset_size"] == 50
    s, d, _ = training_pairs(trs[-1])
    np.testing.assert_array_equal(model.state_dict()["data/x"][-38:], np.concatenate([s, d], 1))


def test_deterministic_given_seed(make_transitions):
    trs = _data(make_transitions, members=2)
    runs = []
    for seed in (3, 3, 4):
        m = InverseDynamics(4, 2, 2, InverseDynamicsConfig(seed=seed))
        m.add(trs)
        runs.append((m.train(50), m.label(trs[0].state, query_displacement(trs[0]))))
    assert runs[0][0] == runs[1][0]
    np.testing.assert_array_equal(runs[0][1], runs[1][1])
    assert runs[0][0] != runs[2][0]


def test_label_keeps_leading_dims_and_range(make_transitions):
    m = InverseDynamics(4, 2, 2)
    m.add(_data(make_transitions, members=1))
    out = m.label(np.zeros((3, 7, 4)), 100.0 * np.ones((3, 7, 2)))
    assert out.shape == (3, 7, 2) and out.dtype == np.float32 and np.all(np.abs(out) <= 1)


def test_state_dict_roundtrip_through_safetensors_resumes_exactly(make_transitions, tmp_path):
    trs = _data(make_transitions, members=2)
    a = InverseDynamics(4, 2, 2, InverseDynamicsConfig(seed=5))
    a.add(trs)
    a.train(30)
    save_file(a.state_dict(), str(tmp_path / "m.safetensors"))
    b = InverseDynamics(4, 2, 2, InverseDynamicsConfig(seed=123))
    b.load_state_dict(load_file(str(tmp_path / "m.safetensors")))
    assert b.iterations == 30
    assert a.train(20) == b.train(20)  # same data, optimizer state and RNG
    np.testing.assert_array_equal(a.label(trs[1].state, query_displacement(trs[1])),
                                  b.label(trs[1].state, query_displacement(trs[1])))
    light = a.state_dict(with_training=False)
    assert not any(k.startswith(("data/", "optim/", "rng/")) for k in light)
    c = InverseDynamics.from_state_dict(light)
    np.testing.assert_array_equal(c.label(trs[0].state, query_displacement(trs[0])),
                                  a.label(trs[0].state, query_displacement(trs[0])))
    with pytest.raises(ValueError, match="hidden"):
        InverseDynamics(4, 2, 2, InverseDynamicsConfig(hidden=(8,))).load_state_dict(light)


def test_background_training_matches_foreground(make_transitions):
    trs = _data(make_transitions, members=2)
    fg = InverseDynamics(4, 2, 2, InverseDynamicsConfig(seed=2))
    fg.add(trs)
    expected = fg.train(200)
    bg = InverseDynamics(4, 2, 2, InverseDynamicsConfig(seed=2))
    bg.add(trs)
    out: list[float] = []
    th = threading.Thread(target=lambda: out.extend(bg.train(200)))
    th.start()
    while th.is_alive():
        assert np.all(np.isfinite(bg.label(trs[0].state, query_displacement(trs[0]))))
    th.join()
    assert out == expected


def test_rejects_mismatched_dims(make_transitions):
    tr = make_transitions(np.random.default_rng(0), obs_dim=3)
    with pytest.raises(ValueError, match="dims"):
        InverseDynamics(4, 2, 2).add([tr])
    with pytest.raises(ValueError, match="position"):
        InverseDynamics(4, 0, 2)


def test_config_validation():
    with pytest.raises(ValueError, match="hidden"):
        InverseDynamicsConfig(hidden=(20, 0))
    with pytest.raises(ValueError, match="max_dataset"):
        InverseDynamicsConfig(max_dataset=0)
