"""M_phi's ``step_change`` input (``shaping/mphi_inputs.change_block``): the displacement's change from the last
step, which a second-order body's action shows in where the displacement itself is mostly the old velocity."""

import numpy as np
import pytest

from helpers import point_mass
from shaped_es.guides.probe_rollouts import query
from shaped_es.shaping.forward_servo import ForwardServo
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import MphiLabels
from shaped_es.shaping.mphi_inputs import change_block, clip_norm, query_change, query_inputs, target_pairs
from shaped_es.shaping.settings import InverseDynamicsConfig

def held_out_r2(step_change: bool, steps: int = 500) -> float:
    cfg = InverseDynamicsConfig(frame="world", min_return=-1e9, seed=0, step_change=step_change)
    m = InverseDynamics(4, 2, 2, cfg)
    m.add([point_mass(1)])
    m.train(steps)
    s, d, y = target_pairs(point_mass(2), "world", step_change=step_change)
    a = m.label(s, d)
    return float(1 - ((a - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum())


def test_a_weakly_actuated_second_order_body_is_fitted_with_the_change():
    plain, change = held_out_r2(False), held_out_r2(True)
    assert change > 0.9 and change > plain + 0.2, (plain, change)


def test_the_change_block():
    tr = point_mass(0, episodes=2, steps=5)
    s, d, a = target_pairs(tr, "world", step_change=True)
    s0, d0, _ = target_pairs(tr, "world")
    assert d.shape == (8, 4) and np.allclose(d[:, :2], d0)
    p = tr.position.astype(np.float64)
    # row 1 of episode 0: (p2 - p1) - (p1 - p0); an episode's first row: its displacement (no last step)
    assert np.allclose(d[1, 2:], (p[2] - p[1]) - (p[1] - p[0]), atol=1e-6)
    assert np.allclose(d[4, 2:], p[6] - p[5], atol=1e-6)  # episode 1 starts at row 5 (row 4 of the pairs)
    assert np.allclose(change_block(np.ones((2, 2)), np.full((2, 2), 0.25), np.array([1, 4])), [[0.75] * 2, [0.0] * 2])
    q = np.array([[1.0, 0.0, 0.5, 0.5]], np.float32)  # frame both: the world displacement first
    assert np.allclose(query_change(q, np.array([[0.25, 0.25]]), 2), [[1.0, 0.0, 0.5, 0.5, 0.75, -0.25]])


def test_asked_with_the_clipped_query_and_the_last_step():
    tr = point_mass(0, episodes=2, steps=20)
    m = InverseDynamics(4, 2, 2, InverseDynamicsConfig(frame="world", min_return=-1e9, step_change=True))
    m.add([tr])
    m.train(50)
    inp = query_inputs(tr, "world", step_change=True)
    assert inp.shape == (40, 4) and m.query_dim == 4 and m.displacement_dim == 2
    q = clip_norm(inp[:, :2], 0.1)
    expect = m.label(tr.state, np.concatenate([q, q - inp[:, 2:]], axis=1))
    assert np.allclose(m.ask(tr.state, inp, 0.1), expect)
    labels = MphiLabels(m, "world")
    labels.max_displacement = 0.1
    assert labels.last_width == 2 and np.allclose(labels(tr.state, labels.inputs(tr)), expect)
    # the probe's label-driven episodes ask the same online: the query, then the last step
    pos, prev, wp = np.array([[1.0, 2.0]]), np.array([[0.5, 2.0]]), np.zeros((1, 2))
    assert np.allclose(query(pos, wp, prev, "world", last_too=True), [[-1.0, -2.0, 0.5, 0.0]])


def test_only_frames_that_start_with_the_world_displacement_and_never_a_forward_model():
    for frame, width in (("world", 4), ("both", 6), ("motion", 2), ("waypoint", 2)):
        m = InverseDynamics(4, 2, 2, InverseDynamicsConfig(frame=frame, step_change=True))
        assert m.query_dim == width and m.step_change == (frame in ("world", "both"))
    f = ForwardServo(4, 2, 2, InverseDynamicsConfig(step_change=True))
    assert not f.step_change and f.in_dim == 6


def test_a_checkpoint_keeps_it():
    m = InverseDynamics(4, 2, 2, InverseDynamicsConfig(frame="world", min_return=-1e9, step_change=True))
    m.add([point_mass(0, episodes=2, steps=20)])
    m.train(10)
    back = InverseDynamics.from_state_dict(m.state_dict(), m.config)
    s = np.zeros((3, 4), np.float32)
    assert np.allclose(back.label(s, np.ones((3, 4), np.float32)), m.label(s, np.ones((3, 4), np.float32)))
    with pytest.raises(Exception):
        InverseDynamics.from_state_dict(m.state_dict(), InverseDynamicsConfig(frame="world"))
