"""Waypoint rules of CarNav-v0, per car and step (paper Sec. III: the agent is rewarded for passing
global waypoints; local waypoints lie "between the agent and the next global waypoint, reachable by the
agent" and are the ``w_t`` of the inverse-dynamics model ``M_phi(s_t, w_t)``).

Routes are dense polylines (``planner.py``); global waypoint ``j = 1..H`` is dense point
``min(j * stride, n - 1)``.

Reached / skipped (:func:`advance`): the next global waypoint ``k`` is *reached* when the car's centre
passes within ``reach_radius`` of it during the step (distance from the swept segment), which pays the
waypoint reward and moves ``k`` on; it is *skipped* (no reward) when the car is past its gate -- the
line through it perpendicular to the route -- within ``skip_width`` of it, so a car that drifts off by
more than the radius never has to turn back. Several waypoints can go in one step.

Local waypoint (:func:`local_index`, the ``info["waypoint"]`` of the env contract): the car's progress
``p`` is its nearest dense route point, searched forward from the previous one within ``_WINDOW``
points; the local waypoint is dense point ``min(p + ahead, g_k)`` with ``ahead = local_lookahead /
dense_step`` -- the point ``local_lookahead`` metres ahead of the car along the route, but never beyond
the next global waypoint ``g_k``. With 1.5 m spacing it is the next global waypoint; with sparse
waypoints it lies between the car and it.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_WINDOW = 24  # dense points searched ahead for the car's projection on its route (12 m at 0.5 m)


@nb.njit(cache=True, inline="always")
def global_index(j, stride, n):
    """Dense index of global waypoint ``j`` (1-based)."""
    return min(j * stride, n - 1)


@nb.njit(cache=True)
def advance(x0, y0, x1, y1, route, n, stride, k, H, reach, skip):
    """Waypoint rule for a step from (x0, y0) to (x1, y1): -> (new k, waypoints reached)."""
    reached = 0
    while k <= H:
        g = global_index(k, stride, n)
        wx, wy = route[g, 0], route[g, 1]
        sx, sy = x1 - x0, y1 - y0
        s2 = sx * sx + sy * sy
        t = 0.0 if s2 < 1e-18 else min(1.0, max(0.0, ((wx - x0) * sx + (wy - y0) * sy) / s2))
        if math.hypot(x0 + t * sx - wx, y0 + t * sy - wy) <= reach:  # passed within the radius
            reached += 1
            k += 1
            continue
        a, b = max(g - 1, 0), min(g + 1, n - 1)
        tx, ty = route[b, 0] - route[a, 0], route[b, 1] - route[a, 1]
        tl = math.hypot(tx, ty) + 1e-12
        along = ((x1 - wx) * tx + (y1 - wy) * ty) / tl
        lateral = abs((x1 - wx) * ty - (y1 - wy) * tx) / tl
        if along > 0.0 and lateral <= skip:  # crossed the gate outside the radius: skipped
            k += 1
            continue
        break
    return k, reached


@nb.njit(cache=True)
def local_index(x, y, route, n, p, g, ahead):
    """Car's progress (nearest dense point from ``p`` on) and the local waypoint's dense index."""
    best, bd = p, np.inf
    for q in range(p, min(p + _WINDOW, n)):
        d = (route[q, 0] - x) ** 2 + (route[q, 1] - y) ** 2
        if d < bd:
            best, bd = q, d
    return best, min(best + ahead, g)
