"""CarlaNav-v0's 32 lidar beams: a one-channel horizontal ``sensor.lidar.ray_cast`` binned by angle.

The sensor (:func:`lidar_attributes`) sweeps 360 degrees once per tick (``rotation_frequency = 1/dt``)
with ``beams`` rays per sweep (``points_per_second = beams/dt``), no drop-off (general rate 0, and
``dropoff_zero_intensity`` 0 so the intensity rule keeps every point) and no noise. A measurement's
``raw_data`` is float32 ``(N, 4)``: x (forward), y (right), z (up), intensity in the sensor's
(left-handed) frame, one row per ray that hit something.

Binning (:func:`bin_ranges`): beam ``j`` covers the sector of width ``2 pi / beams`` centred on
``2 pi j / beams`` counter-clockwise from straight ahead (CarNav-v0's beam order: j = 0 ahead, then to
the left); its reading is the smallest horizontal range of the points in the sector, capped at
``lidar_range``, and an empty sector (no ray hit) reads ``lidar_range``. Points inside the car's own
box grown by ``margin`` are dropped, so the sensor never reports the ego vehicle.
"""

from __future__ import annotations

import numpy as np

LIDAR_BLUEPRINT = "sensor.lidar.ray_cast"


def lidar_attributes(beams: int, dt: float, max_range: float) -> dict[str, str]:
    """Blueprint attributes (``ActorBlueprint.set_attribute`` takes strings) of the 32-beam scan."""
    return {
        "channels": "1",
        "range": f"{max_range:g}",  # metres
        "points_per_second": str(int(round(beams / dt))),
        "rotation_frequency": f"{1.0 / dt:g}",  # one full sweep per tick
        "upper_fov": "0",
        "lower_fov": "0",
        "horizontal_fov": "360",
        "dropoff_general_rate": "0",
        "dropoff_zero_intensity": "0",  # keep probability of a weak point: 1 - 0 = 1
        "noise_stddev": "0",
        "sensor_tick": "0",  # every tick
    }


def points_of(raw_data: bytes | memoryview | np.ndarray) -> np.ndarray:
    """``LidarMeasurement.raw_data`` as float32 ``(N, 4)`` rows (x, y, z, intensity)."""
    flat = np.frombuffer(raw_data, dtype=np.float32)
    if flat.size % 4:
        raise ValueError(f"lidar raw_data holds {flat.size} float32 values, not a multiple of 4")
    return flat.reshape(-1, 4)  # (4N,) -> (N, 4)


def bin_ranges(points: np.ndarray, beams: int, max_range: float, ego_half: tuple[float, float] = (0.0, 0.0),
               margin: float = 0.0) -> np.ndarray:
    """Range ``(beams,)`` float64 of each beam (metres, in ``[0, max_range]``) from sensor points ``(N, 4)``
    of a lidar at the centre of the car's box; ``ego_half``: the box's half length and width (points
    within it grown by ``margin`` are dropped).
    """
    out = np.full(beams, float(max_range))
    if len(points) == 0:
        return out
    x, y = points[:, 0].astype(np.float64), -points[:, 1].astype(np.float64)  # (N,) env frame: y left
    own = (np.abs(x) <= ego_half[0] + margin) & (np.abs(y) <= ego_half[1] + margin)
    x, y = x[~own], y[~own]
    width = 2.0 * np.pi / beams
    sector = np.floor(np.mod(np.arctan2(y, x) + 0.5 * width, 2.0 * np.pi) / width).astype(np.int64) % beams
    np.minimum.at(out, sector, np.minimum(np.hypot(x, y), max_range))
    return out
