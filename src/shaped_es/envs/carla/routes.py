"""Global planner of CarlaNav-v0 over the map's lane topology (the ``agents`` package and its
``GlobalRoutePlanner`` are not in the ``carla`` wheel, so routes are planned here).

Graph (:func:`topology_segments`, :class:`RoadGraph`): ``Map.get_topology()`` lists lane segments as
(entry, exit) waypoint pairs; each becomes a directed edge whose geometry is sampled by walking
``Waypoint.next(step)`` from the entry until the exit is within one step. Segment ends closer than
``join_tol`` (3-D, so a bridge never joins the road below it) are one node. Lane changes are not edges:
a route keeps its lane between junctions, as CarNav-v0's routes do.

Route (:meth:`RoadGraph.route`): the start and the destination are located on their lane segments
(by the ``(road_id, section_id, lane_id)`` of ``Map.get_waypoint``, then by projection); A* (networkx,
Euclidean heuristic) joins the start segment's exit node to the destination segment's entry node; the
polyline runs from the start along its segment, the A* segments, and the destination segment up to the
destination. :func:`pick_route` draws seeded destinations until the route length lies in
``route_length``, as CarNav-v0's planner does, and the env resamples the polyline every ``dense_step``
(CarNav-v0's ``_resample``), so global waypoint ``j`` is dense point ``min(j * stride, n - 1)`` there too.

Coordinates are the env's right-handed frame (``frame.py``): ``(x, -y)`` of CARLA's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import networkx as nx
import numpy as np

from shaped_es.envs.carla.frame import location_xyz

SegmentKey = tuple[int, int, int]  # (road_id, section_id, lane_id) of a CARLA waypoint
_MAX_SAMPLES = 200_000  # a segment walk stops here (a lane that never reaches its exit)


@dataclass(frozen=True)
class Located:
    """A point on the graph: segment index and arc length along it (metres)."""

    segment: int
    s: float


def waypoint_key(wp) -> SegmentKey:
    return int(wp.road_id), int(wp.section_id), int(wp.lane_id)


def topology_segments(carla_map, step: float) -> list[tuple[SegmentKey, np.ndarray]]:
    """Every lane segment of ``carla_map`` as ``(key, points (k, 3))`` in the env's frame, sampled every
    ``step`` metres by ``Waypoint.next`` (both ends included)."""
    out = []
    for entry, exit_ in carla_map.get_topology():
        end = location_xyz(exit_.transform.location)
        pts, wp = [location_xyz(entry.transform.location)], entry
        for _ in range(_MAX_SAMPLES):
            if np.linalg.norm(pts[-1] - end) <= step:
                break
            options = wp.next(step)
            if not options:
                break
            same = [w for w in options if waypoint_key(w)[0] == waypoint_key(wp)[0]]
            wp = min(same or options,  # the option that heads for the exit
                     key=lambda w: float(np.linalg.norm(location_xyz(w.transform.location) - end)))
            pts.append(location_xyz(wp.transform.location))
        if np.linalg.norm(pts[-1] - end) > 1e-6:
            pts.append(end)
        out.append((waypoint_key(entry), np.array(pts)))  # (k, 3)
    return out


def _arc(points: np.ndarray) -> np.ndarray:
    """Cumulative arc length ``(k,)`` of a polyline ``(k, 2)``."""
    return np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(points, axis=0).T))])


def _cut(points: np.ndarray, cum: np.ndarray, s0: float, s1: float) -> np.ndarray:
    """The part ``(m, 2)`` of a polyline between arc lengths ``s0 <= s1`` (ends interpolated)."""
    inner = points[(cum > s0) & (cum < s1)]
    ends = [np.array([np.interp(s, cum, points[:, 0]), np.interp(s, cum, points[:, 1])]) for s in (s0, s1)]
    return np.vstack([ends[0], inner, ends[1]])


class RoadGraph:
    """Directed lane graph of a map: segments (polylines in the env's frame) between merged end nodes."""

    def __init__(self, segments: Sequence[tuple[SegmentKey, np.ndarray]], join_tol: float = 0.5):
        if not segments:
            raise ValueError("the map has no lane topology (Map.get_topology() is empty)")
        self.keys = [tuple(k) for k, _ in segments]
        raw = [np.asarray(p, dtype=np.float64) for _, p in segments]  # (k, D) each, D = 2 or 3
        self.points = [p[:, :2] for p in raw]  # (k, 2) each
        self.cum = [_arc(p) for p in self.points]
        ends = np.array([[p[0], p[-1]] for p in raw])  # (S, 2, D) entry and exit of each segment
        self.nodes, node_of = self._join(ends.reshape(-1, ends.shape[-1]), join_tol)  # (N, D), (2S,)
        self.ends = node_of.reshape(-1, 2)  # (2S,) -> (S, 2) node of each segment's entry and exit
        self.graph = nx.DiGraph()
        self.graph.add_nodes_from(range(len(self.nodes)))
        for i, (a, b) in enumerate(self.ends):
            length = float(self.cum[i][-1])
            if not self.graph.has_edge(a, b) or self.graph[a][b]["length"] > length:
                self.graph.add_edge(int(a), int(b), length=length, segment=i)
        self._by_key: dict[SegmentKey, list[int]] = {}
        for i, k in enumerate(self.keys):
            self._by_key.setdefault(k, []).append(i)

    @staticmethod
    def _join(points: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
        """Merge end points ``(E, 3)`` closer than ``tol``: (node positions ``(N, 3)``, node of each)."""
        nodes: list[np.ndarray] = []
        ids = np.empty(len(points), dtype=np.int64)
        for i, p in enumerate(points):
            near = [j for j, q in enumerate(nodes) if np.linalg.norm(q - p) <= tol]
            if near:
                ids[i] = near[0]
            else:
                ids[i] = len(nodes)
                nodes.append(p)
        return np.array(nodes), ids

    def locate(self, xy: Sequence[float], key: SegmentKey | None = None) -> Located:
        """The closest point of the segments with ``key`` (all segments if none has it) to ``xy``."""
        candidates = self._by_key.get(tuple(key), []) if key is not None else []
        best = (math.inf, 0, 0.0)
        for i in candidates or range(len(self.points)):
            d, s = _project(self.points[i], self.cum[i], np.asarray(xy, dtype=np.float64))
            if d < best[0]:
                best = (d, i, s)
        return Located(best[1], best[2])

    def _heuristic(self, u: int, v: int) -> float:
        return float(np.hypot(*(self.nodes[u, :2] - self.nodes[v, :2])))

    def route(self, start: Located, goal: Located) -> np.ndarray | None:
        """The polyline ``(m, 2)`` from ``start`` to ``goal`` along the lanes, or None if unreachable."""
        a, b = start.segment, goal.segment
        if a == b and goal.s > start.s:
            return _cut(self.points[a], self.cum[a], start.s, goal.s)
        try:
            path = nx.astar_path(self.graph, int(self.ends[a, 1]), int(self.ends[b, 0]),
                                 heuristic=self._heuristic, weight="length")
        except nx.NetworkXNoPath:
            return None
        parts = [_cut(self.points[a], self.cum[a], start.s, float(self.cum[a][-1]))]
        parts += [self.points[self.graph[u][v]["segment"]] for u, v in zip(path[:-1], path[1:])]
        parts.append(_cut(self.points[b], self.cum[b], 0.0, goal.s))
        return _dedupe(np.vstack(parts))


def _project(points: np.ndarray, cum: np.ndarray, p: np.ndarray) -> tuple[float, float]:
    """(distance, arc length) of the closest point of polyline ``points (k, 2)`` to ``p``."""
    if len(points) == 1:
        return float(np.hypot(*(points[0] - p))), 0.0
    a, d = points[:-1], np.diff(points, axis=0)  # (k-1, 2) segment starts and directions
    dd = np.maximum((d * d).sum(axis=1), 1e-18)
    t = np.clip(((p - a) * d).sum(axis=1) / dd, 0.0, 1.0)  # (k-1,)
    dist = np.hypot(*(a + t[:, None] * d - p).T)
    i = int(np.argmin(dist))
    return float(dist[i]), float(cum[i] + t[i] * math.sqrt(dd[i]))


def _dedupe(points: np.ndarray) -> np.ndarray:
    """Drop consecutive points closer than 1 mm (segment joins repeat their shared end)."""
    keep = np.concatenate([[True], np.hypot(*np.diff(points, axis=0).T) > 1e-3])
    return points[keep]


def route_length(points: np.ndarray) -> float:
    return float(_arc(points)[-1]) if len(points) > 1 else 0.0


def pick_route(graph: RoadGraph, spots: Sequence[Located], start: int, rng: np.random.Generator,
               length: tuple[float, float], tries: int) -> np.ndarray | None:
    """The route from ``spots[start]`` to a destination among ``spots``: up to ``tries`` destinations
    drawn with ``rng``; the first whose route length lies in ``length``, else the closest to it (None
    if no destination is reachable)."""
    lo, hi = length
    others = [i for i in range(len(spots)) if i != start]
    best, best_bad = None, math.inf
    for _ in range(tries if others else 0):
        dest = others[int(rng.integers(len(others)))]
        line = graph.route(spots[start], spots[dest])
        if line is None or len(line) < 2:
            continue
        total = route_length(line)
        bad = max(lo - total, total - hi, 0.0)
        if bad < best_bad:
            best, best_bad = line, bad
        if bad == 0.0:
            break
    return best
