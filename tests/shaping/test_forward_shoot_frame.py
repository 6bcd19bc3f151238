"""The shooting labels' waypoint frame (shaping/forward_shoot.py): a car that sees only where its waypoint is in
its own frame (no world heading in its state, as CarNav-v0's and a new user's car-and-trailer) has world-frame
paths no model of its state can predict; in the waypoint frame they are a function of the state. The frame's model
predicts held-out paths, its labels steer toward the waypoint, and its aim reads ``(|w - p|, 0)``."""

import numpy as np
import pytest

from helpers import egocentric_car, egocentric_obs as _obs
from shaped_es.data import Transitions
from shaped_es.shaping.forward_shoot import ForwardChunk, ShootLabels, check_frame, shoot_model
from shaped_es.shaping.settings import InverseDynamicsConfig

H = 4


@pytest.fixture(scope="module")
def fitted():
    cfg = InverseDynamicsConfig(hidden=(32, 32), lr=3e-3, seed=0)
    train, test = egocentric_car(), egocentric_car(seed=1)
    out = {}
    for frame in ("world", "waypoint"):
        m = ForwardChunk(2, 2, 2, cfg, horizon=H, frame=frame)
        m.add([train])
        m.train(3000)
        out[frame] = (m, m.unexplained([test]))
    return out


def test_the_waypoint_frame_predicts_an_egocentric_body_the_world_frame_cannot(fitted):
    assert fitted["world"][1] > 0.8  # no heading in the state: the world-frame path is nearly unpredictable
    assert fitted["waypoint"][1] < 0.2 * fitted["world"][1]


def _turns_right_way(labels: ShootLabels, n=40) -> float:
    """The share of ``n`` random states, a waypoint 1.2 rad off the car's nose to one side, where the label turns
    to that side."""
    rng = np.random.default_rng(5)
    ok = 0
    for _ in range(n):
        p, heading, side = rng.normal(size=2), rng.uniform(-np.pi, np.pi), rng.choice([-1.0, 1.0])
        w = p + 0.4 * np.array([np.cos(heading + side * 1.2), np.sin(heading + side * 1.2)])
        f32 = lambda x: np.asarray(x, np.float32)[None]  # noqa: E731
        tr = Transitions(0, 0, np.zeros(1, np.int32), np.zeros(1, np.int32), f32(_obs(p, heading, w)), f32(p),
                         f32(w), np.zeros((1, 2), np.float32), np.zeros(1, np.float32))
        ok += int(np.sign(labels(tr.state, labels.inputs(tr))[0, 1]) == side)
    return ok / n


def test_its_labels_turn_the_car_toward_the_waypoint(fitted):
    """A waypoint to the car's left asks for a left turn, to its right a right turn: always in the waypoint frame,
    about as often as a coin in the world frame."""
    assert _turns_right_way(ShootLabels(fitted["waypoint"][0], 0.0, "min")) == 1.0
    assert _turns_right_way(ShootLabels(fitted["world"][0], 0.0, "min")) < 0.75


def test_the_aim_in_the_waypoint_frame_is_straight_ahead_at_the_waypoints_distance(fitted):
    tr = egocentric_car(n_eps=2, T=5, seed=3)
    got = ShootLabels(fitted["waypoint"][0], 0.0, "min").inputs(tr)[:, :2]  # the aim (its last column: the held-goal flag)
    dist = np.linalg.norm(tr.waypoint - tr.position, axis=1)
    np.testing.assert_allclose(got, np.stack([dist, np.zeros_like(dist)], 1), atol=1e-5)
    world = ShootLabels(fitted["world"][0], 0.0, "min").inputs(tr)[:, :2]  # the world frame's: w - p as it is
    np.testing.assert_allclose(world, tr.waypoint - tr.position, atol=1e-6)


def test_frames_a_model_cannot_use_are_one_line_errors():
    cfg = InverseDynamicsConfig()
    with pytest.raises(ValueError, match="at least two coordinates"):
        ForwardChunk(3, 1, 2, cfg, frame="waypoint")
    with pytest.raises(ValueError, match="one of"):
        check_frame("motion", 2)
    with pytest.raises(ValueError, match="world frame only"):
        shoot_model(3, 2, 2, cfg, kind="rollout", frame="waypoint")
    assert shoot_model(3, 2, 2, cfg, frame="waypoint").frame == "waypoint"


def test_unexplained_is_one_for_the_mean_path_and_none_without_paths(fitted):
    m = fitted["waypoint"][0]
    assert m.unexplained([]) is None
    assert m.unexplained([egocentric_car(n_eps=1, T=H, seed=4)]) is None  # no step with H successors
    mean_model = ForwardChunk(2, 2, 2, InverseDynamicsConfig(), horizon=H, frame="waypoint")
    test = egocentric_car(seed=1)
    mean_model.add([test])  # fixes its scales; predict the mean path by hand below
    x, y, _ = mean_model._pairs(test, np.unique(test.episode))
    mean_model.predict = lambda s, a: np.broadcast_to(y.mean(axis=0), (len(s), y.shape[1])).reshape(len(s), H, 2)
    assert mean_model.unexplained([test]) == pytest.approx(1.0)
