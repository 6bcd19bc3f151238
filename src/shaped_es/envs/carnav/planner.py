"""Global planner of CarNav-v0 (paper Sec. III-IV: the simulator's global planner gives the waypoints,
at resolution 1.5 m; the paper's conclusion names A* as the planner to use when none is given).

Episode sampling (:func:`plan_routes`, one Numba call for B seeds; randomness from a SplitMix64 hash of
the seed only): the seed picks the town, then up to ``route_tries`` (start, destination) pairs, each a
random point on a random open road segment (by length, away from junctions); pairs whose shortest road
distance lies in ``route_length`` are planned, and the first whose driven route (below) lies in it is
kept (else the closest). Start and destination are left on whichever end of their segment makes the
route shortest, so the route never U-turns.

Route: A* over the road graph (Euclidean heuristic) gives the intersections; the centre-line polyline
is shifted ``lane_offset`` to the right (right-hand traffic), every 90-degree turn is rounded by an arc of
``turn_radius``, and the result is resampled every ``dense_step`` (<= 0.5 m). Global waypoint ``j``
(``j = 1..H``) is dense point ``min(j * wp_stride, n - 1)``: one every ``waypoint_spacing`` metres, the
last one at the destination.

The per-step waypoint rules (reached / skipped / local waypoint) are in ``waypoints.py``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_ARC = 12  # points per rounded turn


@nb.njit(cache=True)
def _uniform(seed, k):
    """SplitMix64 hash of (seed, k) -> float in [0, 1): the planner's only source of randomness."""
    z = np.uint64(seed) + np.uint64(k + 1) * np.uint64(0x9E3779B97F4A7C15)
    z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    z = z ^ (z >> np.uint64(31))
    return float(z >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@nb.njit(cache=True)
def all_pairs_shortest(nodes, adj):
    """Floyd-Warshall road distances ``(N, N)`` over the open segments (``adj`` ``(N, 4)``, -1 = none)."""
    n = nodes.shape[0]
    d = np.full((n, n), np.inf)
    for i in range(n):
        d[i, i] = 0.0
        for m in adj[i]:
            if m >= 0:
                d[i, m] = math.hypot(nodes[i, 0] - nodes[m, 0], nodes[i, 1] - nodes[m, 1])
    for k in range(n):
        for i in range(n):
            for j in range(n):
                if d[i, k] + d[k, j] < d[i, j]:
                    d[i, j] = d[i, k] + d[k, j]
    return d


@nb.njit(cache=True)
def astar(nodes, adj, start, goal, path):
    """A* from ``start`` to ``goal`` (Euclidean heuristic); writes the node ids into ``path``, returns
    their count (0 if unreachable)."""
    n = nodes.shape[0]
    g = np.full(n, np.inf)
    f = np.full(n, np.inf)
    came = np.full(n, -1)
    closed = np.zeros(n, dtype=np.bool_)
    g[start] = 0.0
    f[start] = math.hypot(nodes[start, 0] - nodes[goal, 0], nodes[start, 1] - nodes[goal, 1])
    while True:
        cur, best = -1, np.inf
        for i in range(n):  # the open set is small: a linear scan beats a heap here
            if not closed[i] and f[i] < best:
                cur, best = i, f[i]
        if cur < 0:
            return 0
        if cur == goal:
            break
        closed[cur] = True
        for m in adj[cur]:
            if m < 0 or closed[m]:
                continue
            ng = g[cur] + math.hypot(nodes[cur, 0] - nodes[m, 0], nodes[cur, 1] - nodes[m, 1])
            if ng < g[m]:
                g[m], came[m] = ng, cur
                f[m] = ng + math.hypot(nodes[m, 0] - nodes[goal, 0], nodes[m, 1] - nodes[goal, 1])
    count, v = 0, goal
    while v >= 0:
        count += 1
        v = came[v]
    v = goal
    for i in range(count - 1, -1, -1):
        path[i] = v
        v = came[v]
    return count


@nb.njit(cache=True)
def _point_on(nodes, edges, edge_cum, ne, u_edge, u_off, margin):
    """A random point on a random open segment: (segment, node a, node b, offset from a, length)."""
    e = min(np.searchsorted(edge_cum[:ne], u_edge * edge_cum[ne - 1]), ne - 1)
    a, b = edges[e, 0], edges[e, 1]
    length = math.hypot(nodes[b, 0] - nodes[a, 0], nodes[b, 1] - nodes[a, 1])
    m = min(margin, 0.45 * length)
    return e, a, b, m + u_off * (length - 2.0 * m), length


@nb.njit(cache=True)
def _rounded_polyline(pts, n, offset, radius, out):
    """Shift the axis-aligned polyline ``pts[:n]`` right by ``offset``, round its corners; -> count."""
    cnt = 0
    for i in range(n):
        if i == 0 or i == n - 1:  # end points: shift right of their only segment
            a, b = (0, 1) if i == 0 else (n - 2, n - 1)
            dx, dy = pts[b, 0] - pts[a, 0], pts[b, 1] - pts[a, 1]
            ln = math.hypot(dx, dy)
            out[cnt, 0], out[cnt, 1] = pts[i, 0] + offset * dy / ln, pts[i, 1] - offset * dx / ln
            cnt += 1
            continue
        l1 = math.hypot(pts[i, 0] - pts[i - 1, 0], pts[i, 1] - pts[i - 1, 1])
        l2 = math.hypot(pts[i + 1, 0] - pts[i, 0], pts[i + 1, 1] - pts[i, 1])
        d1x, d1y = (pts[i, 0] - pts[i - 1, 0]) / l1, (pts[i, 1] - pts[i - 1, 1]) / l1
        d2x, d2y = (pts[i + 1, 0] - pts[i, 0]) / l2, (pts[i + 1, 1] - pts[i, 1]) / l2
        vx = pts[i, 0] + offset * (d1y + d2y)  # corner of the shifted lines (right normal of d: (dy, -dx))
        vy = pts[i, 1] - offset * (d1x + d2x)
        turn = d1x * d2y - d1y * d2x  # +1 left, -1 right
        a1 = l1 + offset * turn if i - 1 == 0 else 0.5 * (l1 + offset * turn)  # shifted leg available
        a2 = l2 + offset * turn if i + 1 == n - 1 else 0.5 * (l2 + offset * turn)
        r = min(radius, a1, a2)
        cx, cy = vx - r * d1x + r * d2x, vy - r * d1y + r * d2y  # arc centre
        for q in range(_ARC + 1):
            phi = 0.5 * math.pi * q / _ARC
            out[cnt, 0] = cx - r * d2x * math.cos(phi) + r * d1x * math.sin(phi)
            out[cnt, 1] = cy - r * d2y * math.cos(phi) + r * d1y * math.sin(phi)
            cnt += 1
    return cnt


@nb.njit(cache=True)
def _resample(poly, n, step, out):
    """Points every ``step`` metres along ``poly[:n]`` (the last point always kept) -> count (<= cap)."""
    cap = out.shape[0]
    out[0, 0], out[0, 1] = poly[0, 0], poly[0, 1]
    cnt, s_acc, s_next = 1, 0.0, step
    for i in range(n - 1):
        dx, dy = poly[i + 1, 0] - poly[i, 0], poly[i + 1, 1] - poly[i, 1]
        ln = math.hypot(dx, dy)
        if ln < 1e-9:
            continue
        while s_next <= s_acc + ln and cnt < cap:
            t = (s_next - s_acc) / ln
            out[cnt, 0], out[cnt, 1] = poly[i, 0] + t * dx, poly[i, 1] + t * dy
            cnt, s_next = cnt + 1, s_next + step
        s_acc += ln
    if s_acc - (s_next - step) > 1e-6 and cnt < cap:
        out[cnt, 0], out[cnt, 1] = poly[n - 1, 0], poly[n - 1, 1]
        cnt += 1
    return cnt


@nb.njit(cache=True)
def _candidate(seed, t, nodes, dist, edges, cum, ne, lo, hi, margin, cand):
    """Start/destination pair ``t`` of an episode into ``cand`` (start x, y, exit node, destination x, y,
    entry node); returns how far its road distance is outside [lo, hi] (inf: unusable)."""
    u = 1 + 4 * t
    e, a, b, off, ln = _point_on(nodes, edges, cum, ne, _uniform(seed, u), _uniform(seed, u + 1), margin)
    f, c, d, goff, gln = _point_on(nodes, edges, cum, ne, _uniform(seed, u + 2), _uniform(seed, u + 3),
                                   margin)
    best_bad = np.inf
    if e == f and ne > 1:
        return best_bad
    for q in range(4):  # leave the start by either end, enter the destination by either end
        exit_node, other_exit, s_cost = (a, b, off) if q < 2 else (b, a, ln - off)
        entry, other_entry, g_cost = (c, d, goff) if q % 2 == 0 else (d, c, gln - goff)
        total = s_cost + dist[exit_node, entry] + g_cost
        if (total > (ln - s_cost) + dist[other_exit, entry] + g_cost
                or total > s_cost + dist[exit_node, other_entry] + (gln - g_cost)):
            continue  # a shorter way exists (it would U-turn): not the planner's route
        bad = max(lo - total, total - hi, 0.0)
        if bad < best_bad:
            cand[0] = nodes[a, 0] + (nodes[b, 0] - nodes[a, 0]) * off / ln
            cand[1] = nodes[a, 1] + (nodes[b, 1] - nodes[a, 1]) * off / ln
            cand[2] = exit_node
            cand[3] = nodes[c, 0] + (nodes[d, 0] - nodes[c, 0]) * goff / gln
            cand[4] = nodes[c, 1] + (nodes[d, 1] - nodes[c, 1]) * goff / gln
            cand[5] = entry
            best_bad = bad
    return best_bad


@nb.njit(cache=True)
def _build(nodes, adj, cand, offset, radius, step, out):
    """Dense route of a start/destination pair (A*, lane offset, rounded turns) -> (count, length)."""
    path = np.empty(nodes.shape[0], dtype=np.int64)
    npath = astar(nodes, adj, int(cand[2]), int(cand[5]), path)
    pts = np.empty((npath + 2, 2))
    pts[0, 0], pts[0, 1] = cand[0], cand[1]
    n = 1
    for i in range(npath + 1):  # intersections, then the destination; drop collinear points
        px, py = (nodes[path[i], 0], nodes[path[i], 1]) if i < npath else (cand[3], cand[4])
        if n >= 2 and (abs(pts[n - 2, 0] - px) < 1e-9 or abs(pts[n - 2, 1] - py) < 1e-9):
            n -= 1  # pts[n-1] lies on the straight line from pts[n-2] to (px, py)
        pts[n, 0], pts[n, 1] = px, py
        n += 1
    poly = np.empty((n * (_ARC + 1) + 2, 2))
    cnt = _resample(poly, _rounded_polyline(pts, n, offset, radius, poly), step, out)
    last = math.hypot(out[cnt - 1, 0] - out[cnt - 2, 0], out[cnt - 1, 1] - out[cnt - 2, 1])
    return cnt, (cnt - 2) * step + last


@nb.njit(cache=True)
def _plan_one(seed, num_towns, nodes_all, adj_all, dist_all, edges_all, cum_all, ne_all, lo, hi, tries,
              margin, offset, radius, step, out):
    """Town and dense route (written into ``out``) of one episode; returns (town, dense count)."""
    k = min(int(_uniform(seed, 0) * num_towns), num_towns - 1)
    nodes, adj, dist = nodes_all[k], adj_all[k], dist_all[k]
    edges, cum, ne = edges_all[k], cum_all[k], ne_all[k]
    cand, fallback, scratch = np.zeros(6), np.zeros(6), np.empty_like(out)
    fallback_bad, best_bad, best_n = np.inf, np.inf, 0
    for t in range(tries):
        bad = _candidate(seed, t, nodes, dist, edges, cum, ne, lo, hi, margin, cand)
        if bad < fallback_bad:
            fallback[:], fallback_bad = cand, bad
        if bad > 0.0:  # road distance out of range: do not even plan it
            continue
        cnt, length = _build(nodes, adj, cand, offset, radius, step, scratch)
        rbad = max(lo - length, length - hi, 0.0)  # the driven route (lane, rounded turns) decides
        if rbad < best_bad:
            out[:cnt], best_bad, best_n = scratch[:cnt], rbad, cnt
        if rbad == 0.0:
            break
    if best_n == 0:  # no pair in range: the closest one
        best_n = _build(nodes, adj, fallback, offset, radius, step, out)[0]
    return k, best_n


@nb.njit(cache=True)
def _plan_batch(seeds, num_towns, nodes, adj, dist, edges, cum, ne, lo, hi, tries, margin, offset,
                radius, step, town, route, n_dense):
    for i in range(seeds.shape[0]):
        town[i], n_dense[i] = _plan_one(seeds[i], num_towns, nodes, adj, dist, edges, cum, ne, lo, hi,
                                        tries, margin, offset, radius, step, route[i])


def plan_routes(pack, cfg, seeds: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Town ``(B,)`` int64, dense route ``(B, cfg.route_buffer, 2)`` float64 and its length ``(B,)``."""
    seeds = np.asarray(seeds, dtype=np.int64).reshape(-1)
    B = seeds.shape[0]
    town = np.empty(B, dtype=np.int64)
    route = np.zeros((B, cfg.route_buffer, 2))
    n_dense = np.empty(B, dtype=np.int64)
    margin = cfg.road_width / 2 + cfg.turn_radius + 1.0  # start/destination stay clear of junctions
    _plan_batch(seeds, cfg.num_towns, pack.nodes, pack.adj, pack.dist, pack.edges, pack.edge_cum,
                pack.num_edges, cfg.route_length[0], cfg.route_length[1], cfg.route_tries, margin,
                cfg.lane_offset, cfg.turn_radius, cfg.dense_step, town, route, n_dense)
    return town, route, n_dense
