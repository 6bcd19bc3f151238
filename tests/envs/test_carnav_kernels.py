"""CarNav-v0 kernels against independent NumPy references: lidar, collision, planner."""

from types import SimpleNamespace

import numpy as np
import pytest

from shaped_es.envs.carnav.config import make_config
from shaped_es.envs.carnav.core import CarNavCore
from shaped_es.envs.carnav.lidar import build_index, collides, lidar_scan
from shaped_es.envs.carnav.planner import astar
from shaped_es.envs.carnav.waypoints import advance, local_index


def _random_scene(rng, n_boxes=40, size=60.0):
    lo = rng.uniform(0, size, (n_boxes, 2))
    wh = rng.uniform(0.3, 8.0, (n_boxes, 2))
    return np.concatenate([lo, lo + wh], axis=1)  # (NB, 4)


def _pack(boxes, cell, radius, size=60.0):
    origin = np.array([-5.0, -5.0])
    g = int(np.ceil((size + 10) / cell)) + 1
    start, items = build_index(boxes, origin, cell, g, g, radius)
    return SimpleNamespace(boxes=boxes[None], origin=origin[None], cell_start=start[None],
                           cell_items=items[None], grid_shape=(g, g), cell=cell)


def _reference_scan(boxes, ox, oy, yaw, beams, max_range):
    """Brute force: each beam against the 4 edges (segments) of every box, in NumPy."""
    out = np.full(beams, max_range)
    inside = (boxes[:, 0] <= ox) & (ox <= boxes[:, 2]) & (boxes[:, 1] <= oy) & (oy <= boxes[:, 3])
    if inside.any():
        return np.zeros(beams)
    x0, y0, x1, y1 = boxes.T
    starts = np.concatenate([np.stack([x0, y0], 1), np.stack([x1, y0], 1), np.stack([x1, y1], 1),
                             np.stack([x0, y1], 1)])  # (4 NB, 2)
    ends = np.concatenate([np.stack([x1, y0], 1), np.stack([x1, y1], 1), np.stack([x0, y1], 1),
                           np.stack([x0, y0], 1)])  # (4 NB, 2)
    e = ends - starts
    for j in range(beams):
        a = yaw + 2 * np.pi * j / beams
        d = np.array([np.cos(a), np.sin(a)])
        w = starts - np.array([ox, oy])  # (4 NB, 2)
        den = d[0] * (-e[:, 1]) - d[1] * (-e[:, 0])  # det [d, -e]
        ok = np.abs(den) > 1e-12
        t = (w[:, 0] * (-e[:, 1]) - w[:, 1] * (-e[:, 0])) / np.where(ok, den, 1.0)
        s = (d[0] * w[:, 1] - d[1] * w[:, 0]) / np.where(ok, den, 1.0)
        hit = ok & (t >= 0) & (s >= 0) & (s <= 1)
        if hit.any():
            out[j] = min(max_range, t[hit].min())
    return out


@pytest.mark.parametrize("cell", [2.0, 4.0, 7.5])
def test_lidar_matches_brute_force(cell):
    rng = np.random.default_rng(int(cell * 10))
    max_range, beams = 20.0, 32
    for _ in range(5):
        boxes = _random_scene(rng)
        pack = _pack(boxes, cell, max_range)
        B = 64
        x, y, yaw = rng.uniform(0, 60, B), rng.uniform(0, 60, B), rng.uniform(-np.pi, np.pi, B)
        got = lidar_scan(pack, np.zeros(B, np.int64), x, y, yaw, beams, max_range)  # (B, beams)
        want = np.stack([_reference_scan(boxes, x[i], y[i], yaw[i], beams, max_range) for i in range(B)])
        np.testing.assert_allclose(got / max_range, want / max_range, atol=1e-4, rtol=0)
        assert (want < max_range).mean() > 0.3  # the scenes are not empty


def _ref_collides(x, y, yaw, hl, hw, box):
    """Convex polygons overlap iff a vertex of one lies in the other or two edges cross."""
    c, s = np.cos(yaw), np.sin(yaw)
    local = ((hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw))
    car = np.array([[x + c * a - s * b, y + s * a + c * b] for a, b in local])
    x0, y0, x1, y1 = box
    rect = np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]])

    def cr(u, v):
        return u[0] * v[1] - u[1] * v[0]

    def inside(p, poly):
        sign = [cr(poly[(i + 1) % 4] - poly[i], p - poly[i]) for i in range(4)]
        return all(v >= 0 for v in sign) or all(v <= 0 for v in sign)

    def cross(p1, p2, q1, q2):
        d = lambda a, b, c: cr(b - a, c - a)  # noqa: E731
        return d(p1, p2, q1) * d(p1, p2, q2) < 0 and d(q1, q2, p1) * d(q1, q2, p2) < 0

    if any(inside(p, rect) for p in car) or any(inside(q, car) for q in rect):
        return True
    pairs = [(i, j) for i in range(4) for j in range(4)]
    return any(cross(car[i], car[(i + 1) % 4], rect[j], rect[(j + 1) % 4]) for i, j in pairs)


def test_collision_matches_polygon_reference():
    rng = np.random.default_rng(1)
    agree, positives = 0, 0
    for _ in range(600):
        box = np.concatenate([lo := rng.uniform(-3, 3, 2), lo + rng.uniform(0.2, 4, 2)])
        x, y, yaw = rng.uniform(-4, 6), rng.uniform(-4, 6), rng.uniform(-np.pi, np.pi)
        got = collides(x, y, yaw, 2.25, 0.95, box[None], np.zeros(1, np.int32), 0, 1)
        want = _ref_collides(x, y, yaw, 2.25, 0.95, box)
        agree += got == want
        positives += want
    assert agree == 600 and 150 < positives < 450  # both outcomes well represented


@pytest.fixture(scope="module")
def core():
    return CarNavCore(make_config("default"))


def test_routes_keep_clearance_and_spacing(core):
    cfg = core.config
    state, _, _ = core.reset(np.arange(48))
    clear = cfg.car_width / 2 + 0.5
    for i in range(48):
        pts = state.route[i, : state.n_dense[i]]  # (n, 2)
        boxes = core.pack.towns[state.town[i]].boxes  # (NB, 4)
        lo, hi = boxes[None, :, :2], boxes[None, :, 2:]  # (1, NB, 2)
        gap = np.maximum(0, np.maximum(lo - pts[:, None], pts[:, None] - hi))  # (n, NB, 2)
        assert np.linalg.norm(gap, axis=-1).min() >= clear  # every route point stays clear of every obstacle
        wps = state.route_waypoints(i, cfg.wp_stride)  # (H, 2)
        gaps = np.linalg.norm(np.diff(np.concatenate([pts[:1], wps]), axis=0), axis=1)
        assert np.all(gaps[:-1] <= cfg.waypoint_spacing + 1e-9)
        assert np.all(gaps[:-1] > 0.9 * cfg.waypoint_spacing)
        length = np.linalg.norm(np.diff(pts, axis=0), axis=1).sum()
        assert cfg.route_length[0] - 0.1 <= length <= cfg.route_length[1] + 0.1


def test_astar_is_shortest(core):
    pack = core.pack
    rng = np.random.default_rng(0)
    for _ in range(30):
        k = int(rng.integers(len(pack.towns)))
        nodes = pack.towns[k].nodes
        a, b = rng.integers(len(nodes), size=2)
        path = np.empty(len(nodes), np.int64)
        n = astar(nodes, pack.adj[k, : len(nodes)], int(a), int(b), path)
        steps = np.linalg.norm(np.diff(nodes[path[:n]], axis=0), axis=1)
        assert path[0] == a and path[n - 1] == b
        np.testing.assert_allclose(steps.sum(), pack.dist[k, a, b], rtol=1e-12)
        edges = {tuple(sorted(e)) for e in pack.towns[k].edges.tolist()}
        assert all(tuple(sorted((int(p), int(q)))) in edges for p, q in zip(path[: n - 1], path[1:n]))


def test_waypoint_rules_on_a_straight_route():
    route = np.stack([np.arange(0, 30.5, 0.5), np.zeros(61)], axis=1)  # (61, 2) along +x, dense step 0.5
    stride, H = 3, 20  # global waypoint j at x = 1.5 j
    # passing waypoint 1 (x = 1.5) within 0.5 m: reached; waypoints are counted within one step too
    assert advance(1.0, 0.3, 2.0, 0.3, route, 61, stride, 1, H, 0.5, 3.5) == (2, 1)
    assert advance(0.0, 0.0, 3.2, 0.0, route, 61, stride, 1, H, 0.5, 3.5) == (3, 2)
    # crossing its gate 1 m off the route: skipped without reward; 5 m off: neither
    assert advance(1.0, 1.0, 2.0, 1.0, route, 61, stride, 1, H, 0.5, 3.5) == (2, 0)
    assert advance(1.0, 5.0, 2.0, 5.0, route, 61, stride, 1, H, 0.5, 3.5) == (1, 0)
    # not there yet
    assert advance(0.0, 0.0, 0.9, 0.0, route, 61, stride, 1, H, 0.5, 3.5) == (1, 0)
    # local waypoint: 3 m (6 dense points) ahead of the car's projection, capped at the next global one
    assert local_index(4.1, 0.2, route, 61, 0, 30, 6) == (8, 14)
    assert local_index(4.1, 0.2, route, 61, 0, 9, 6) == (8, 9)
