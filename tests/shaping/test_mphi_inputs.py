"""M_phi's inputs (shaping/mphi_inputs.py): training pairs within episodes (one step, hindsight, matched),
the return filter, and the queries (raw, at the agent's own pace)."""

from __future__ import annotations

import numpy as np
import pytest

from shaped_es.data import Transitions
from shaped_es.shaping import inverse_dynamics, mphi_inputs
from shaped_es.shaping.inverse_dynamics import InverseDynamics, InverseDynamicsConfig
from shaped_es.shaping.mphi_inputs import (
    episode_end,
    kept_episodes,
    query_displacement,
    target_pairs,
    training_pairs,
)

B = np.array([[0.5, 0.2], [-0.1, 0.4]])  # position_{t+1} - position_t = B a_t


def test_the_helpers_stay_importable_from_inverse_dynamics():
    for name in ("episode_end", "target_pairs", "kept_episodes", "training_pairs", "mixed_query",
                 "query_displacement"):
        assert getattr(inverse_dynamics, name) is getattr(mphi_inputs, name), name


def test_training_pairs_use_next_position_within_episode(make_transitions):
    tr = make_transitions(np.random.default_rng(0), episodes=2, steps=5, B=B)
    s, d, a = training_pairs(tr)
    assert s.shape == (8, 4) and d.shape == (8, 2) and a.shape == (8, 2)  # last step of each episode dropped
    np.testing.assert_allclose(d, a @ B.T, atol=1e-5)
    np.testing.assert_allclose(query_displacement(tr), tr.action @ B.T, atol=1e-5)


def _line(T=10, speed=1.0, waypoint_ahead=3.0, episodes=1):
    """Straight-line episodes moving ``speed`` per step along x, waypoint ``waypoint_ahead`` ahead."""
    ep = np.repeat(np.arange(episodes), T).astype(np.int32)
    st = np.tile(np.arange(T), episodes).astype(np.int32)
    pos = np.stack([st * speed, np.zeros(T * episodes)], axis=1).astype(np.float32)  # (T, 2)
    wp = pos + np.array([waypoint_ahead, 0], np.float32)
    z = np.zeros((T * episodes, 3), np.float32)
    return Transitions(0, 0, ep, st, z, pos, wp, np.zeros((T * episodes, 2), np.float32),
                       np.array([1.0, -2.0] * (T * episodes // 2), np.float32))


def test_target_pairs_one_step_hindsight_and_matched():
    tr = _line(T=10, speed=1.0, waypoint_ahead=3.0, episodes=2)
    np.testing.assert_array_equal(episode_end(tr), [9] * 10 + [19] * 10)
    s, d, a = target_pairs(tr, "world", "one_step")
    assert s.shape == (18, 3)  # the last step of each episode has no successor
    np.testing.assert_allclose(d[:, 0], 1.0)
    s, d, a = target_pairs(tr, "world", "matched", horizon=8)
    np.testing.assert_allclose(d[:9, 0], [3, 3, 3, 3, 3, 3, 3, 2, 1])  # the query distance, or the episode end
    s, d, a = target_pairs(tr, "world", "hindsight", horizon=4, rng=np.random.default_rng(0))
    assert set(np.unique(d[:, 0])) <= {1.0, 2.0, 3.0, 4.0} and len(np.unique(d[:, 0])) >= 3
    assert np.all(d[:9, 0] <= 9 - np.arange(9))  # never past the episode's end
    _, d2, _ = target_pairs(tr, "world", "hindsight", horizon=4, rng=np.random.default_rng(0))
    np.testing.assert_array_equal(d, d2)


def test_chunk_targets_hold_the_mean_action_over_the_horizon():
    tr = _line(T=10, speed=1.0, episodes=2)
    tr.action[:] = np.arange(20, dtype=np.float32)[:, None] * [1.0, -1.0]  # a_t = (t, -t), t counted over both episodes
    s, d, a = target_pairs(tr, "world", "chunk", horizon=4)
    assert s.shape == (18, 3) and a.shape == (18, 2)
    np.testing.assert_allclose(d[:9, 0], [4, 4, 4, 4, 4, 4, 3, 2, 1])  # p_{t+4} - p_t, cut at the episode's end
    np.testing.assert_allclose(a[:9, 0], [1.5, 2.5, 3.5, 4.5, 5.5, 6.5, 7, 7.5, 8])  # mean of a_t..a_{t+h-1}
    np.testing.assert_allclose(a[9:, 0], [11.5, 12.5, 13.5, 14.5, 15.5, 16.5, 17, 17.5, 18])  # no step of episode 0
    np.testing.assert_allclose(a[:, 1], -a[:, 0])


def test_return_filters():
    tr = _line(T=10, episodes=2)  # rewards alternate +1, -2: total -5, positive part +5 per episode
    assert kept_episodes(tr, 5.0, "total")[1].size == 0
    np.testing.assert_array_equal(kept_episodes(tr, 5.0, "positive")[1], [0, 1])
    np.testing.assert_array_equal(kept_episodes(tr, 1e9, "none")[1], [0, 1])
    m = InverseDynamics(3, 2, 2, InverseDynamicsConfig(min_return=5.0, filter="total"))
    assert m.add([tr])["added"] == 0
    m = InverseDynamics(3, 2, 2, InverseDynamicsConfig(min_return=5.0, filter="positive", targets="matched"))
    assert m.add([tr])["added"] == 18


def test_own_step_queries_point_at_the_waypoint_at_the_agents_pace(make_transitions):
    tr = make_transitions(np.random.default_rng(3), episodes=2, steps=6, B=B)
    raw = query_displacement(tr)
    q = query_displacement(tr, scale="own_step")
    step = np.linalg.norm(np.diff(tr.position, axis=0), axis=1)  # (T-1,) |p_{t+1} - p_t|
    want = np.empty(len(tr))
    for t in range(len(tr)):
        last = t + 1 == len(tr) or tr.episode[t + 1] != tr.episode[t]
        want[t] = step[t - 1] if last else step[t]  # an episode's last step: the step into it
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), want, rtol=1e-5)
    cos = (q * raw).sum(1) / (np.linalg.norm(q, axis=1) * np.linalg.norm(raw, axis=1))
    np.testing.assert_allclose(cos, 1.0, atol=1e-5)  # the raw query's direction
    with pytest.raises(ValueError, match="query scale must be one of"):
        query_displacement(tr, scale="far")
    with pytest.raises(ValueError, match="query_scale must be one of"):
        InverseDynamicsConfig(query_scale="far")
