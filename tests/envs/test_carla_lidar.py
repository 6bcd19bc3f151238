"""CarlaNav-v0's lidar: raw point buffers ``(N, 4)`` float32 binned into 32 beams, exact values."""

import numpy as np
import pytest

from shaped_es.envs.carla.lidar import bin_ranges, lidar_attributes, points_of


def raw(*rows) -> bytes:
    return np.array(rows, dtype=np.float32).tobytes()  # (N, 4) float32, as LidarMeasurement.raw_data


def test_sensor_attributes_give_one_horizontal_sweep_of_32_rays_per_tick():
    a = lidar_attributes(32, 0.1, 20.0)
    assert a == {"channels": "1", "range": "20", "points_per_second": "320", "rotation_frequency": "10",
                 "upper_fov": "0", "lower_fov": "0", "horizontal_fov": "360", "dropoff_general_rate": "0",
                 "dropoff_zero_intensity": "0", "noise_stddev": "0", "sensor_tick": "0"}
    assert all(isinstance(v, str) for v in a.values())  # set_attribute takes strings


def test_points_of_reads_float32_rows_and_rejects_a_torn_buffer():
    pts = points_of(raw([1, 2, 3, 0.5], [4, 5, 6, 1]))
    assert pts.dtype == np.float32 and pts.shape == (2, 4) and pts[1, 2] == 6
    assert points_of(b"").shape == (0, 4)
    with pytest.raises(ValueError, match="not a multiple of 4"):
        points_of(np.zeros(6, np.float32).tobytes())


def test_binning_by_sector_with_carnav_beam_order():
    # sensor frame is CARLA's: x ahead, y RIGHT. Beam j looks 2 pi j / 32 counter-clockwise (to the left).
    pts = points_of(raw([5, 0, 0, 1],  # ahead: beam 0
                        [0, -8, 0, 1],  # left (y < 0): beam 8
                        [0, 3, 0, 1],  # right: beam 24
                        [-2, 0, 0, 1], [-6, 0.1, 0, 1],  # behind: beam 16, the nearer one wins
                        [30, 0.5, 0, 1]))  # beyond range: capped (and beam 0 keeps its 5 m)
    r = bin_ranges(pts, 32, 20.0)
    expect = np.full(32, 20.0)
    expect[[0, 8, 24, 16]] = [5.0, 8.0, 3.0, 2.0]
    np.testing.assert_allclose(r, expect)


def test_sector_edges_are_half_a_beam_either_side():
    width = 2 * np.pi / 32
    ang = np.array([0.49 * width, 0.51 * width, -0.49 * width, -0.51 * width])  # env angles (+ left)
    pts = np.stack([10 * np.cos(ang), -10 * np.sin(ang), np.zeros(4), np.ones(4)], 1).astype(np.float32)
    for a, p in zip(ang, pts):
        r = bin_ranges(p[None], 32, 20.0)
        beam = int(np.flatnonzero(r < 20.0)[0])
        assert beam == {0.49: 0, 0.51: 1, -0.49: 0, -0.51: 31}[round(a / width, 2)]


def test_empty_scan_reads_max_range_and_own_body_is_dropped():
    np.testing.assert_array_equal(bin_ranges(np.zeros((0, 4), np.float32), 32, 20.0), np.full(32, 20.0))
    body = points_of(raw([2.0, 0.5, 0, 1], [2.6, 0, 0, 1]))  # inside the 2.4 x 1.0 half box + 0.1, then not
    r = bin_ranges(body, 32, 20.0, ego_half=(2.4, 1.0), margin=0.1)
    expect = np.full(32, 20.0)
    expect[0] = 2.6
    np.testing.assert_allclose(r, expect, rtol=1e-6)
