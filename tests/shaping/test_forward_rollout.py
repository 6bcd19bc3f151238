"""The rollout model (shaping/forward_rollout.py) on the shooting tests' body, ``p' = p + v``, ``v' = 0.9 v + 0.1
R a``, whose observation is its velocity: one step of the observation and the position, learned, rolled out
with an action held, gives the held action's path; the shooting labels through it head for the waypoint; its
scales round-trip; and ``shoot_model`` builds either model."""

import numpy as np
import pytest

from shaped_es.shaping.forward_rollout import ForwardRollout
from shaped_es.shaping.forward_shoot import ForwardChunk, ShootLabels, candidate_actions, shoot_model
from shaped_es.shaping.settings import InverseDynamicsConfig

from test_forward_shoot import ROT, _episodes, _held_paths

H = 6


def _model(seed=0) -> ForwardRollout:
    return ForwardRollout(2, 2, 2, InverseDynamicsConfig(hidden=(32, 32), lr=3e-3, seed=seed), horizon=H)


@pytest.fixture(scope="module")
def model():
    m = _model()
    m.add([_episodes()])
    m.train(6000)
    return m


def test_the_rolled_out_path_is_the_held_actions(model):
    rng = np.random.default_rng(1)
    v, a = 0.05 * rng.normal(size=(100, 2)), rng.uniform(-1, 1, size=(100, 2))
    want = _held_paths(v, a, H)
    got = model.paths(v.astype(np.float32), a.astype(np.float32))  # (100, H, 2)
    assert got.shape == (100, H, 2)
    assert np.abs(got - want).mean() < 0.15 * np.abs(want).mean()
    s1, dp = model.step(v.astype(np.float32), a.astype(np.float32))  # one step: the next velocity, the move
    assert s1.shape == (100, 2) and dp.shape == (100, 2)
    assert np.abs(s1 - (0.9 * v + 0.1 * a @ ROT.T)).mean() < 0.15 * np.abs(0.1 * a).mean()
    assert model.dataset_size == 60 * 39 and (model.obs_scale > 0).all() and model.step_scale > 0


def test_shooting_labels_through_it_head_for_the_waypoint(model):
    err = np.array([[0.0, 0.3], [0.3, 0.0], [-0.2, 0.2]], np.float32)  # w - p, at rest
    a = ShootLabels(model)(np.zeros((3, 2), np.float32), err)  # the nearest pass
    moved = a @ ROT.T
    cos = (moved * err).sum(1) / np.linalg.norm(moved, axis=1) / np.linalg.norm(err, axis=1)
    assert (cos > 0.9).all()
    assert {tuple(r) for r in a.tolist()} <= {tuple(r) for r in candidate_actions(2).tolist()}


def test_state_round_trips_and_a_bad_scale_is_refused(model):
    fresh = _model(seed=5)
    assert not ShootLabels(fresh).ready
    fresh.load_state_dict(model.state_dict())
    np.testing.assert_array_equal(fresh.obs_scale, model.obs_scale)
    s, q = np.zeros((4, 2), np.float32), np.full((4, 2), 0.2, np.float32)
    np.testing.assert_array_equal(ShootLabels(fresh)(s, q), ShootLabels(model)(s, q))
    bad = model.state_dict()
    bad["rollout/obs_scale"] = np.array([1.0, -1.0])
    with pytest.raises(ValueError, match="observation scales"):
        _model().load_state_dict(bad)


def test_shoot_model_builds_either_kind():
    cfg = InverseDynamicsConfig(frame="both")
    assert type(shoot_model(3, 2, 2, cfg, 8)) is ForwardChunk
    m = shoot_model(3, 2, 2, cfg, 8, kind="rollout")
    assert type(m) is ForwardRollout and m.horizon == 8 and m.config.frame == "world" and m.act_dim == 5
    with pytest.raises(ValueError, match="shooting model"):
        shoot_model(3, 2, 2, cfg, 8, kind="tree")
