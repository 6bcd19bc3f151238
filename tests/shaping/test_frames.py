import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping.frames import motion_angle, to_frame
from shaped_es.shaping.mphi_inputs import query_displacement, training_pairs


def _car(theta: float) -> Transitions:
    """A planar agent driving an arc, the whole scene rotated by ``theta``."""
    t = np.arange(12)
    pts = np.stack([np.sin(0.2 * t) * 5, (1 - np.cos(0.2 * t)) * 5], axis=1)  # (T, 2)
    R = np.array([[np.cos(theta), -np.sin(theta)], [np.sin(theta), np.cos(theta)]])
    pos = (pts @ R.T).astype(np.float32)
    wp = (pts[np.minimum(t + 3, 11)] @ R.T).astype(np.float32)
    z = np.zeros(12, np.int32)
    return Transitions(0, 0, z, t.astype(np.int32), np.zeros((12, 3), np.float32), pos, wp,
                       np.zeros((12, 2), np.float32), np.zeros(12, np.float32))


def test_motion_frame_removes_the_world_rotation():
    a, b = _car(0.0), _car(1.1)
    for fn in (lambda tr, f: training_pairs(tr, f)[1], query_displacement):
        np.testing.assert_allclose(fn(a, "motion")[1:], fn(b, "motion")[1:], atol=1e-4)
        assert not np.allclose(fn(a, "world"), fn(b, "world"), atol=1e-2)


def test_motion_angle_and_identity_in_world_frame():
    tr = _car(0.0)
    ang = motion_angle(tr)
    assert ang[0] == 0.0 and ang.shape == (12,)
    d = tr.position[2] - tr.position[1]
    assert np.isclose(ang[2], np.arctan2(d[1], d[0]))
    disp = np.random.default_rng(0).normal(size=(12, 2)).astype(np.float32)
    assert to_frame(tr, disp, "world") is disp
    rotated = to_frame(tr, disp, "motion")
    np.testing.assert_allclose(np.linalg.norm(rotated, axis=1), np.linalg.norm(disp, axis=1), rtol=1e-5)


def test_waypoint_frame_puts_the_query_on_x_and_removes_the_world_rotation():
    a, b = _car(0.0), _car(1.1)
    q = query_displacement(a, "waypoint")  # (T, 2): straight to the waypoint
    dist = np.linalg.norm(a.waypoint - a.position, axis=1)
    np.testing.assert_allclose(q[:, 0], dist, atol=1e-5)
    np.testing.assert_allclose(q[:, 1], 0.0, atol=1e-5)
    for fn in (lambda tr, f: training_pairs(tr, f)[1], query_displacement):
        np.testing.assert_allclose(fn(a, "waypoint"), fn(b, "waypoint"), atol=1e-4)  # defined at t = 0 too
    # a step to the waypoint's left has a positive y in its frame
    tr = _car(0.0)
    left = to_frame(tr, np.tile([[0.0, 1.0]], (12, 1)).astype(np.float32), "waypoint")
    ang = np.arctan2(tr.waypoint[:, 1] - tr.position[:, 1], tr.waypoint[:, 0] - tr.position[:, 0])
    np.testing.assert_allclose(left[:, 1], np.cos(ang), atol=1e-5)
