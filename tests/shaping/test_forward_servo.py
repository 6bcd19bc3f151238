"""The servo rival's forward model and labels (shaping/forward_servo.py), on a known second-order body:
the model learns ``p_{t+1} - p_t = v_t + 0.1 R a_t`` (R a rotation: the action's frame is not the world's),
the labels push toward the waypoint through the learned action direction, the drift damps them, and the
state round-trips."""

import numpy as np
import pytest

from shaped_es.data import Transitions
from shaped_es.shaping.forward_servo import ServoLabels, servo_model
from shaped_es.shaping.settings import InverseDynamicsConfig

ROT = np.array([[0.0, -1.0], [1.0, 0.0]])  # the action's x moves the body along world y


def _episodes(n_eps=40, T=50, seed=0) -> Transitions:
    """A point mass: velocity v in the state, p' = p + v + 0.1 R a, v' = 0.9 v + 0.1 R a; random actions."""
    rng = np.random.default_rng(seed)
    S, P, W, A, ep, st = [], [], [], [], [], []
    for e in range(n_eps):
        p, v, w = rng.normal(size=2), 0.05 * rng.normal(size=2), rng.normal(size=2)
        for t in range(T):
            a = rng.uniform(-1, 1, size=2)
            S.append(v.copy()), P.append(p.copy()), W.append(w.copy()), A.append(a), ep.append(e), st.append(t)
            step = v + 0.1 * ROT @ a
            p, v = p + step, 0.9 * v + 0.1 * ROT @ a
    f32 = lambda x: np.asarray(x, np.float32)  # noqa: E731
    return Transitions(0, 0, np.array(ep, np.int32), np.array(st, np.int32), f32(S), f32(P), f32(W), f32(A),
                       np.zeros(len(st), np.float32))


@pytest.fixture(scope="module")
def model():
    m = servo_model(2, 2, 2, InverseDynamicsConfig(hidden=(32, 32), lr=3e-3), seed=0)
    m.add([_episodes()])
    m.train(6000)
    return m


def test_the_forward_model_learns_the_step(model):
    rng = np.random.default_rng(1)
    v, a = 0.05 * rng.normal(size=(200, 2)), rng.uniform(-1, 1, size=(200, 2))
    want = v + 0.1 * a @ ROT.T  # (200, 2)
    got = model.predict(v.astype(np.float32), a.astype(np.float32))
    assert np.abs(got - want).mean() < 0.1 * np.abs(want).mean()
    assert model.step_scale > 0 and model.query_scale > 0


def test_labels_move_toward_the_waypoint_through_the_learned_direction(model):
    lab = ServoLabels(model, gain=1.0, damping=0.0)
    err = np.array([[0.0, 0.3], [0.3, 0.0], [-0.2, 0.2]], np.float32)  # w - p, at rest
    a = lab(np.zeros((3, 2), np.float32), err)
    moved = a @ ROT.T  # (3, 2) where the action moves the body
    cos = (moved * err).sum(1) / np.linalg.norm(moved, axis=1) / np.linalg.norm(err, axis=1)
    assert (cos > 0.95).all()
    assert np.abs(a).max() <= 1.0


def test_the_drift_damps_the_label(model):
    err = np.array([[0.0, 0.3]], np.float32)  # the waypoint is along world y
    toward = np.array([[0.0, 0.08]], np.float32)  # already moving toward it
    damped, plain = ServoLabels(model, 1.0, 3.0), ServoLabels(model, 1.0, 0.0)
    push = lambda lab, v: float((lab(v, err) @ ROT.T)[0, 1])  # noqa: E731 - the label's push along y
    assert push(damped, toward) < push(plain, toward)
    assert push(damped, toward) < push(damped, np.zeros((1, 2), np.float32))


def test_state_round_trips_and_bad_scales_are_refused(model):
    fresh = servo_model(2, 2, 2, InverseDynamicsConfig(hidden=(32, 32), lr=3e-3), seed=5)
    fresh.load_state_dict(model.state_dict())
    s, q = np.zeros((4, 2), np.float32), np.full((4, 2), 0.2, np.float32)
    np.testing.assert_array_equal(ServoLabels(fresh)(s, q), ServoLabels(model)(s, q))
    assert ServoLabels(fresh).ready
    bad = model.state_dict() | {"servo/scales": np.array([np.nan, 1.0])}
    with pytest.raises(ValueError, match="servo scales"):
        fresh.load_state_dict(bad)


def test_an_untrained_model_is_not_ready():
    m = servo_model(2, 2, 2, InverseDynamicsConfig(), seed=0)
    assert not ServoLabels(m).ready
