"""CARLA's frame to the env's (CarNav-v0's) frame, and the vehicle's state in it.

CARLA (Unreal) is left-handed: x forward/east, y right/south, z up, yaw in degrees from +x towards +y
(clockwise seen from above), angular velocity in deg/s. The env's frame is right-handed like CarNav-v0's:
``(x, -y)``, yaw in radians counter-clockwise, yaw rate + counter-clockwise (so a left turn is +, as in
CarNav-v0). Every function takes CARLA objects by duck typing (``.x/.y/.z``, ``.yaw``), never imports
``carla``.
"""

from __future__ import annotations

import math

import numpy as np


def location_xyz(loc) -> np.ndarray:
    """A ``carla.Location``/``Vector3D`` as ``(3,)`` in the env's frame."""
    return np.array([float(loc.x), -float(loc.y), float(loc.z)])


def yaw_of(rotation) -> float:
    """A ``carla.Rotation``'s yaw (degrees, clockwise) as the env's yaw (radians, counter-clockwise,
    wrapped to [-pi, pi))."""
    return (-math.radians(float(rotation.yaw)) + math.pi) % (2.0 * math.pi) - math.pi


def body_velocity(velocity, yaw: float) -> tuple[float, float]:
    """(forward, lateral + left) m/s of a world-frame ``carla.Vector3D`` velocity, for env yaw ``yaw``."""
    vx, vy = float(velocity.x), -float(velocity.y)
    c, s = math.cos(yaw), math.sin(yaw)
    return c * vx + s * vy, -s * vx + c * vy


def yaw_rate_of(angular_velocity) -> float:
    """The env's yaw rate (rad/s, + counter-clockwise) from ``Actor.get_angular_velocity()`` (deg/s
    about CARLA's z, + clockwise seen from above)."""
    return -math.radians(float(angular_velocity.z))


def steer_command(steer: float) -> float:
    """The env's steer action (+1 = full left, CarNav-v0's sign) as ``VehicleControl.steer`` (+1 = right)."""
    return -min(1.0, max(-1.0, float(steer)))
