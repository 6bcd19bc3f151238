"""CarlaNav-v0's per-step terms from given poses and velocities (exact values): CARLA's frame to the
env's, controls with the speed limit, reward terms, waypoint progress and the observation, which must
equal CarNav-v0's for the same car state."""

import math

import numpy as np
import pytest
from carla_double import Rotation, Vector3D

from shaped_es.envs.carla.config import make_config
from shaped_es.envs.carla.frame import body_velocity, location_xyz, steer_command, yaw_of, yaw_rate_of
from shaped_es.envs.carla.terms import CarState, RouteProgress, control_values, observation, reward_terms
from shaped_es.envs.carnav.config import make_config as carnav_config
from shaped_es.envs.carnav.observation import obs_scales

CFG = make_config()


def test_frame_flips_y_yaw_and_yaw_rate():
    np.testing.assert_allclose(location_xyz(Vector3D(3.0, 4.0, 0.5)), [3.0, -4.0, 0.5])
    assert yaw_of(Rotation(yaw=90.0)) == pytest.approx(-math.pi / 2)  # CARLA +y (south) is env -y
    assert yaw_of(Rotation(yaw=-90.0)) == pytest.approx(math.pi / 2)
    assert yaw_of(Rotation(yaw=180.0)) == pytest.approx(-math.pi)  # wrapped to [-pi, pi)
    assert yaw_rate_of(Vector3D(0, 0, 90.0)) == pytest.approx(-math.pi / 2)  # deg/s -> rad/s, sign flips
    assert steer_command(1.0) == -1.0 and steer_command(-0.25) == 0.25 and steer_command(3.0) == -1.0


def test_body_velocity_forward_and_left():
    yaw = yaw_of(Rotation(yaw=90.0))  # heading CARLA +y
    fwd, lat = body_velocity(Vector3D(0.0, 5.0, 0.0), yaw)
    assert (fwd, lat) == pytest.approx((5.0, 0.0))
    fwd, lat = body_velocity(Vector3D(2.0, 0.0, 0.0), 0.0)  # heading east, moving east
    assert (fwd, lat) == pytest.approx((2.0, 0.0))
    fwd, lat = body_velocity(Vector3D(0.0, -1.5, 0.0), 0.0)  # CARLA -y is north: the car's left
    assert (fwd, lat) == pytest.approx((0.0, 1.5))


def test_controls_and_the_speed_limit():
    limit = 25 / 3.6
    assert control_values(0.5, 0.8, limit - 0.1, CFG) == (-0.5, 0.8, 0.0)
    assert control_values(-1.0, -0.25, 3.0, CFG) == (1.0, 0.0, 0.25)
    assert control_values(0.0, 1.0, limit + 0.1, CFG) == (-0.0, 0.0, 1.0)  # auto brake 8 / max 8
    soft = make_config(auto_brake=2.0)
    assert control_values(0.0, 1.0, limit + 0.1, soft) == (-0.0, 0.0, 0.25)
    assert control_values(0.0, -0.5, limit + 0.1, soft) == (-0.0, 0.0, 0.5)


def test_reward_terms_are_carnavs():
    H = 80
    assert reward_terms(2, H, False, CFG) == pytest.approx((2 * 250 / 80, -0.1, 0.0))
    assert reward_terms(0, H, True, CFG) == pytest.approx((0.0, -0.1, -50.0))
    assert sum(reward_terms(1, 1000, False, make_config("paper"))) == pytest.approx(1.0 - 0.1)


def test_progress_reaches_skips_and_places_the_local_waypoint():
    route = np.stack([np.arange(0, 30.5, 0.5), np.zeros(61)], 1)  # 30 m straight, dense 0.5 m
    p = RouteProgress(route, CFG)
    assert (p.num_waypoints, p.stride, p.ahead) == (20, 3, 6)
    p.locate(0.0, 0.0)
    np.testing.assert_array_equal(p.waypoint(), [1.5, 0.0])  # the next global waypoint (1.5 m spacing)
    assert p.move(0.0, 0.0, 3.2, 0.1) == 2 and p.k == 3  # passed 1.5 and 3.0 within 0.5 m
    assert p.move(3.2, 0.1, 4.7, 2.0) == 0 and p.k == 4  # 4.5 crossed 2 m off: skipped, no reward
    p.locate(4.7, 0.0)
    np.testing.assert_array_equal(p.waypoint(), [6.0, 0.0])
    assert p.reached == 2 and not p.done


def test_observation_matches_carnav_layout_and_scales():
    car = CarState(x=0.0, y=0.0, yaw=0.0, v_long=3.0, v_lat=-0.5, yaw_rate=0.2, odometer=17.0)
    ranges = np.full(32, 20.0)
    ranges[0], ranges[8] = 5.0, 25.0
    obs = observation(car, np.array([3.0, 4.0]), ranges, CFG)
    odo, v, w = obs_scales(carnav_config())  # CarNav-v0's scales: the same numbers
    expect = [0.8, 0.6, 17.0 * odo, 3.0 * v, -0.5 * v, 0.2 * w]
    assert obs.dtype == np.float32 and obs.shape == (38,)
    np.testing.assert_allclose(obs[:6], expect, rtol=1e-6)
    assert obs[6] == pytest.approx(0.25) and obs[14] == 1.0 and obs[7] == 1.0
    assert obs_scales(CFG) == obs_scales(carnav_config())
    fast = observation(CarState(0, 0, 0, -30.0, 30.0, -9.0, 1e6), np.array([1.0, 0.0]), ranges, CFG)
    np.testing.assert_array_equal(fast[2:6], [1.0, -1.0, 1.0, -1.0])  # clipped as CarNav-v0's
