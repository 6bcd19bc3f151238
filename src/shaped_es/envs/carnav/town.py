"""Procedural towns for CarNav-v0 (our stand-in for CARLA Town07, paper Sec. IV) and their packed arrays.

A town is a lattice of ``nx x ny`` intersections with random block sizes; neighbouring intersections
are joined by straight two-lane roads, a fraction of which are closed (the town stays connected).
Everything that is not road is obstacle, as axis-aligned boxes ``[xmin, ymin, xmax, ymax]``:

- buildings inside each block, set back ``setback`` metres from the road edge, split by alleys;
- props (poles, bins) on the verge between the road edge and the building line, away from junctions;
- a box filling every closed road segment, and a wall around the town.

So every point within ``road_width / 2`` of an open road's centre line is free, and every obstacle is
at least ``road_width / 2 + 0.3`` m from it. The road graph (intersections, open segments) feeds the
planner (``planner.py``); the boxes feed the lidar and collision kernels (``lidar.py``).

A family of ``num_towns`` towns is generated from ``town_seed`` and packed into padded arrays
(:class:`TownPack`), cached per process, so B cars in B different towns step in one kernel call.
"""

from __future__ import annotations

from dataclasses import dataclass
import numpy as np

from shaped_es.envs.carnav.config import CarNavConfig
from shaped_es.envs.carnav.lidar import build_index
from shaped_es.envs.carnav.planner import all_pairs_shortest


@dataclass(frozen=True)
class Town:
    """One town: road graph and obstacles."""

    nodes: np.ndarray  # (N, 2) float64 intersection positions
    edges: np.ndarray  # (E, 2) int32 open road segments (node ids)
    boxes: np.ndarray  # (NB, 4) float64 obstacles [xmin, ymin, xmax, ymax]
    extent: np.ndarray  # (4,) float64 [xmin, ymin, xmax, ymax] of the walled area (walls included)


def _connected(n: int, edges: list[tuple[int, int]]) -> bool:
    adj: list[list[int]] = [[] for _ in range(n)]
    for a, b in edges:
        adj[a].append(b)
        adj[b].append(a)
    seen, stack = {0}, [0]
    while stack:
        for m in adj[stack.pop()]:
            if m not in seen:
                seen.add(m)
                stack.append(m)
    return len(seen) == n


def _split(rng: np.random.Generator, lo: float, hi: float, parts: int) -> list[tuple[float, float]]:
    """Split [lo, hi] into ``parts`` pieces separated by 2-4 m alleys."""
    if parts == 1:
        return [(lo, hi)]
    cut = lo + (hi - lo) * rng.uniform(0.35, 0.65)
    gap = rng.uniform(2.0, 4.0) / 2
    return [(lo, cut - gap), (cut + gap, hi)]


def generate_town(cfg: CarNavConfig, index: int) -> Town:
    """Town ``index`` of the family ``cfg.town_seed`` (deterministic)."""
    rng = np.random.default_rng([cfg.town_seed, index])
    nx, ny = cfg.grid_nodes
    xs = np.concatenate([[0.0], np.cumsum(rng.uniform(*cfg.block_size, nx - 1))])  # (nx,)
    ys = np.concatenate([[0.0], np.cumsum(rng.uniform(*cfg.block_size, ny - 1))])  # (ny,)
    nodes = np.stack(np.meshgrid(xs, ys, indexing="ij"), axis=-1).reshape(-1, 2)  # (nx*ny, 2), id i*ny+j
    nid = lambda i, j: i * ny + j  # noqa: E731
    lattice = [(nid(i, j), nid(i + 1, j)) for i in range(nx - 1) for j in range(ny)]
    lattice += [(nid(i, j), nid(i, j + 1)) for i in range(nx) for j in range(ny - 1)]
    open_edges = list(lattice)
    for e in rng.permutation(len(lattice)):
        if rng.uniform() < cfg.edge_drop:
            trial = [x for x in open_edges if x != lattice[e]]
            if _connected(nx * ny, trial):
                open_edges = trial
    closed = set(lattice) - set(open_edges)

    hw = cfg.road_width / 2
    h = hw + cfg.setback  # road centre line -> building line
    boxes: list[tuple[float, float, float, float]] = []
    for i in range(nx - 1):  # buildings, block by block
        for j in range(ny - 1):
            if rng.uniform() < cfg.empty_lot_prob:
                continue
            x0, x1, y0, y1 = xs[i] + h, xs[i + 1] - h, ys[j] + h, ys[j + 1] - h
            count = int(rng.integers(cfg.buildings_per_block[0], cfg.buildings_per_block[1] + 1))
            px = 2 if count >= 3 or (count == 2 and rng.uniform() < 0.5) else 1
            py = 2 if count >= 3 or (count == 2 and px == 1) else 1
            cells = [(a, b) for a in _split(rng, x0, x1, px) for b in _split(rng, y0, y1, py)]
            for k in rng.permutation(len(cells))[:count]:
                (a0, a1), (b0, b1) = cells[k]
                inset = rng.uniform(0.0, 1.5, 4)  # irregular building lines, never closer to the road
                boxes.append((a0 + inset[0], b0 + inset[1], a1 - inset[2], b1 - inset[3]))
    for a, b in lattice:  # props on the verges of open roads, closed roads filled
        (ax, ay), (bx, by) = nodes[a], nodes[b]
        horizontal = ay == by
        if (a, b) in closed:
            boxes.append((ax + h, ay - h, bx - h, ay + h) if horizontal else (ax - h, ay + h, ax + h, by - h))
            continue
        lo, hi = (ax, bx) if horizontal else (ay, by)
        for _ in range(int(rng.integers(cfg.props_per_block[0], cfg.props_per_block[1] + 1))):
            size = rng.uniform(0.4, min(1.2, cfg.setback - 0.4))
            along = rng.uniform(lo + h + cfg.turn_radius, hi - h - cfg.turn_radius - size)
            side = rng.choice([-1.0, 1.0])
            off = rng.uniform(hw + 0.3, h - size) if side > 0 else -rng.uniform(hw + 0.3 + size, h)
            if horizontal:
                boxes.append((along, ay + off, along + size, ay + off + size))
            else:
                boxes.append((ax + off, along, ax + off + size, along + size))
    t = cfg.wall_thickness
    X0, X1, Y0, Y1 = xs[0] - h, xs[-1] + h, ys[0] - h, ys[-1] + h
    boxes += [(X0 - t, Y0 - t, X1 + t, Y0), (X0 - t, Y1, X1 + t, Y1 + t),
              (X0 - t, Y0, X0, Y1), (X1, Y0, X1 + t, Y1)]
    return Town(
        nodes=nodes.astype(np.float64),
        edges=np.array(sorted(open_edges), dtype=np.int32),
        boxes=np.array(boxes, dtype=np.float64),
        extent=np.array([X0 - t, Y0 - t, X1 + t, Y1 + t]),
    )


@dataclass(frozen=True)
class TownPack:
    """``K`` towns in padded arrays (one kernel call serves cars in different towns)."""

    towns: tuple[Town, ...]
    nodes: np.ndarray  # (K, N, 2) float64
    adj: np.ndarray  # (K, N, 4) int32 neighbours over open roads (-1: none)
    dist: np.ndarray  # (K, N, N) float64 shortest road distance between intersections
    edges: np.ndarray  # (K, E, 2) int32 open road segments (padded with 0)
    edge_cum: np.ndarray  # (K, E) float64 cumulative segment length (sampling by length; padded with +inf)
    num_edges: np.ndarray  # (K,) int32
    boxes: np.ndarray  # (K, NB, 4) float64 (padded with empty far boxes)
    origin: np.ndarray  # (K, 2) float64 lower-left corner of each town's spatial index
    cell_start: np.ndarray  # (K, GX * GY + 1) int32 CSR offsets into cell_items, per cell
    cell_items: np.ndarray  # (K, L) int32 per cell, the boxes within max(lidar range, car half diagonal)
    grid_shape: tuple[int, int]  # (GX, GY) cells of the spatial index (the largest town's)
    cell: float  # cell side (m)


def _adjacency(n: int, edges: np.ndarray) -> np.ndarray:
    adj = np.full((n, 4), -1, dtype=np.int32)
    deg = np.zeros(n, dtype=np.int64)
    for a, b in edges:
        adj[a, deg[a]], adj[b, deg[b]] = b, a
        deg[a] += 1
        deg[b] += 1
    return adj


def _pad(arrays: list[np.ndarray], fill) -> np.ndarray:
    shape = tuple(max(a.shape[d] for a in arrays) for d in range(arrays[0].ndim))
    out = np.full((len(arrays), *shape), fill, dtype=arrays[0].dtype)
    for k, a in enumerate(arrays):
        out[(k, *(slice(0, s) for s in a.shape))] = a
    return out


def _town_key(cfg: CarNavConfig) -> tuple:
    names = ("num_towns", "town_seed", "grid_nodes", "block_size", "road_width", "setback", "edge_drop",
             "buildings_per_block", "empty_lot_prob", "props_per_block", "turn_radius", "wall_thickness",
             "lidar_range", "lidar_cell", "car_length", "car_width")
    return tuple(getattr(cfg, n) for n in names)


_PACKS: dict[tuple, TownPack] = {}


def town_pack(cfg: CarNavConfig) -> TownPack:
    """The packed town family of ``cfg`` (built once per process and town configuration)."""
    key = _town_key(cfg)
    if key not in _PACKS:
        _PACKS[key] = _build_pack(cfg)
    return _PACKS[key]


def _build_pack(cfg: CarNavConfig) -> TownPack:
    towns = tuple(generate_town(cfg, k) for k in range(cfg.num_towns))
    size = max(float(max(t.extent[2] - t.extent[0], t.extent[3] - t.extent[1])) for t in towns)
    gx = gy = int(np.ceil(size / cfg.lidar_cell)) + 1
    origins, starts, items = [], [], []
    radius = max(cfg.lidar_range, 0.5 * float(np.hypot(cfg.car_length, cfg.car_width)) + 0.1)  # scan, collide
    for t in towns:
        origin = t.extent[:2].copy()
        s, it = build_index(t.boxes, origin, cfg.lidar_cell, gx, gy, radius)
        origins.append(origin)
        starts.append(s)
        items.append(it)
    far = np.array([1e6, 1e6, 1e6 + 1, 1e6 + 1])  # padding box nobody can see
    boxes = _pad([t.boxes for t in towns], 0.0)
    for k, t in enumerate(towns):
        boxes[k, len(t.boxes):] = far
    adj = [_adjacency(len(t.nodes), t.edges) for t in towns]
    lengths = [np.linalg.norm(t.nodes[t.edges[:, 1]] - t.nodes[t.edges[:, 0]], axis=1) for t in towns]
    return TownPack(
        towns=towns,
        nodes=_pad([t.nodes for t in towns], 0.0),
        adj=_pad(adj, -1),
        dist=_pad([all_pairs_shortest(t.nodes, a) for t, a in zip(towns, adj)], np.inf),
        edges=_pad([t.edges for t in towns], 0),
        edge_cum=_pad([np.cumsum(ln) for ln in lengths], np.inf),
        num_edges=np.array([len(t.edges) for t in towns], dtype=np.int32),
        boxes=boxes,
        origin=np.stack(origins),
        cell_start=np.stack(starts),
        cell_items=_pad(items, 0),
        grid_shape=(gx, gy),
        cell=float(cfg.lidar_cell),
    )
