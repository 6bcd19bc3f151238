"""Quadratic Bezier waypoints of the UR5 task (paper, Sec. IV "UR5 Robot arm in ROS Gazebo").

``B(t) = (1 - t)^2 P0 + 2 (1 - t) t P1 + t^2 P2`` for ``t`` in ``[0, 1]`` (second-order Bernstein
polynomials): P0 is the start end-effector position, P1 the fixed control point (0.75, 0.15, 0.45),
P2 the target. The task's H waypoints are ``B(k / (H - 1))``, ``k = 0..H-1``: the first is the start,
the last the target.
"""

from __future__ import annotations

import numpy as np


def bezier_point(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, t: np.ndarray) -> np.ndarray:
    """``B(t)``; ``p0, p1, p2`` ``(..., 3)`` and ``t`` ``(...)`` broadcast together -> ``(..., 3)``."""
    t = np.asarray(t, dtype=np.float64)[..., None]  # (..., 1)
    s = 1.0 - t
    return s * s * p0 + 2.0 * s * t * p1 + t * t * p2  # quadratic Bernstein form (paper, Sec. IV)


def waypoint_t(index: np.ndarray, num_waypoints: int) -> np.ndarray:
    """Curve parameter of waypoint ``index`` (0-based, clipped to the last): ``k / (H - 1)``."""
    k = np.minimum(np.asarray(index), num_waypoints - 1)
    return k / (num_waypoints - 1)


def bezier_waypoints(p0: np.ndarray, p1: np.ndarray, p2: np.ndarray, num_waypoints: int) -> np.ndarray:
    """All H waypoints: ``p0, p2`` ``(B, 3)``, ``p1`` ``(3,)`` -> ``(B, H, 3)``."""
    t = np.linspace(0.0, 1.0, num_waypoints)  # (H,)
    p0 = np.asarray(p0, dtype=np.float64)[..., None, :]  # (B, 1, 3)
    p2 = np.asarray(p2, dtype=np.float64)[..., None, :]  # (B, 1, 3)
    return bezier_point(p0, np.asarray(p1, dtype=np.float64), p2, t)  # (B, H, 3)
