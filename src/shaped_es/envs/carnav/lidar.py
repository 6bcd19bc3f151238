"""Lidar and collision kernels of CarNav-v0 over a per-cell spatial index of axis-aligned boxes.

The paper's state holds a 32-beam lidar scan (Sec. IV, "Carla Driving simulator"); here the beams are
evenly spread over 360 degrees, beam ``j`` at ``yaw + 2 pi j / beams`` (counter-clockwise, beam 0 straight
ahead), from the car's centre, and a reading is the exact distance to the first box hit, capped at
``lidar_range``.

Spatial index: the town is cut into square cells; cell ``c`` lists every box whose distance to the
cell's square is at most ``lidar_range`` (CSR arrays ``cell_start``, ``cell_items``). A ray of length
``lidar_range`` from any point of the cell can only hit those boxes, so the scan tests exactly that
short list -- all beams against one box at a time in a branch-free, SIMD-friendly inner loop (ray/box
slab test) -- instead of every box of the town. The same list serves the car/box collision test
(separating-axis test of the car's oriented rectangle against each box).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

_TINY = 1e-12  # direction components are kept at least this far from 0 (finite slab parameters)


def build_index(boxes: np.ndarray, origin: np.ndarray, cell: float, gx: int, gy: int,
                radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Per-cell lists of the boxes within ``radius`` of the cell.

    boxes ``(NB, 4)``; cell ``(ix, iy)`` is the square ``origin + cell * [ix, ix+1] x [iy, iy+1]`` and has
    flat id ``ix * gy + iy``. Returns ``cell_start`` ``(gx * gy + 1,)`` int32 and ``cell_items`` int32.
    """
    cells, ids = [], []
    for b, (x0, y0, x1, y1) in enumerate(boxes):
        ix = np.arange(max(0, int((x0 - radius - origin[0]) // cell)),
                       min(gx, int((x1 + radius - origin[0]) // cell) + 1))
        iy = np.arange(max(0, int((y0 - radius - origin[1]) // cell)),
                       min(gy, int((y1 + radius - origin[1]) // cell) + 1))
        if ix.size == 0 or iy.size == 0:
            continue
        cx0 = origin[0] + cell * ix  # (nx,) cell left edges
        cy0 = origin[1] + cell * iy  # (ny,)
        dx = np.maximum(0.0, np.maximum(x0 - (cx0 + cell), cx0 - x1))  # (nx,) gap box <-> cell along x
        dy = np.maximum(0.0, np.maximum(y0 - (cy0 + cell), cy0 - y1))  # (ny,)
        near = dx[:, None] ** 2 + dy[None, :] ** 2 <= radius**2  # (nx, ny)
        ii, jj = np.nonzero(near)
        cells.append(ix[ii] * gy + iy[jj])
        ids.append(np.full(ii.size, b))
    cell_ids = np.concatenate(cells) if cells else np.zeros(0, np.int64)
    box_ids = np.concatenate(ids) if ids else np.zeros(0, np.int64)
    order = np.argsort(cell_ids, kind="stable")
    start = np.zeros(gx * gy + 1, dtype=np.int32)
    np.cumsum(np.bincount(cell_ids, minlength=gx * gy), out=start[1:])
    return start, box_ids[order].astype(np.int32)


@nb.njit(cache=True, inline="always")
def cell_of(x, y, ox, oy, cell, gx, gy):
    """Flat cell id of point (x, y), or -1 outside the index."""
    ix = int(math.floor((x - ox) / cell))
    iy = int(math.floor((y - oy) / cell))
    if ix < 0 or iy < 0 or ix >= gx or iy >= gy:
        return -1
    return ix * gy + iy


@nb.njit(cache=True, fastmath=True)
def scan_into(ox, oy, yaw, beam_cos, beam_sin, boxes, items, i0, i1, max_range, inv_x, inv_y, out):
    """Ranges of all beams from (ox, oy) against boxes ``items[i0:i1]``, written into ``out`` (metres).

    beam_cos/beam_sin ``(nb,)``: beam directions relative to the car; inv_x/inv_y ``(nb,)`` scratch.
    """
    n = beam_cos.shape[0]
    c, s = math.cos(yaw), math.sin(yaw)
    for j in range(n):
        dx = c * beam_cos[j] - s * beam_sin[j]
        dy = s * beam_cos[j] + c * beam_sin[j]
        inv_x[j] = 1.0 / (dx if abs(dx) > _TINY else (_TINY if dx >= 0 else -_TINY))
        inv_y[j] = 1.0 / (dy if abs(dy) > _TINY else (_TINY if dy >= 0 else -_TINY))
        out[j] = max_range
    r2 = max_range * max_range
    for it in range(i0, i1):
        b = items[it]
        x0, y0, x1, y1 = boxes[b, 0] - ox, boxes[b, 1] - oy, boxes[b, 2] - ox, boxes[b, 3] - oy
        gx_ = max(0.0, max(x0, -x1))
        gy_ = max(0.0, max(y0, -y1))
        if gx_ * gx_ + gy_ * gy_ > r2:  # box entirely out of range
            continue
        for j in range(n):  # slab test, branch-free (vectorizes over beams)
            ta, tb = x0 * inv_x[j], x1 * inv_x[j]
            tc, td = y0 * inv_y[j], y1 * inv_y[j]
            t_near = max(max(min(ta, tb), min(tc, td)), 0.0)
            t_far = min(max(ta, tb), max(tc, td))
            hit = t_far >= t_near
            out[j] = min(out[j], t_near) if hit else out[j]


@nb.njit(cache=True, fastmath=True)
def collides(x, y, yaw, half_len, half_wid, boxes, items, i0, i1):
    """True if the car's rectangle (centre x, y; heading yaw) overlaps a box of ``items[i0:i1]``."""
    c, s = math.cos(yaw), math.sin(yaw)
    ac, as_ = abs(c), abs(s)
    ext_x = ac * half_len + as_ * half_wid  # car's half extent along world x
    ext_y = as_ * half_len + ac * half_wid
    for it in range(i0, i1):
        b = items[it]
        hx, hy = 0.5 * (boxes[b, 2] - boxes[b, 0]), 0.5 * (boxes[b, 3] - boxes[b, 1])
        dx, dy = 0.5 * (boxes[b, 0] + boxes[b, 2]) - x, 0.5 * (boxes[b, 1] + boxes[b, 3]) - y
        if abs(dx) > ext_x + hx or abs(dy) > ext_y + hy:  # world axes separate
            continue
        if abs(dx * c + dy * s) > half_len + ac * hx + as_ * hy:  # car's forward axis separates
            continue
        if abs(-dx * s + dy * c) > half_wid + as_ * hx + ac * hy:  # car's lateral axis separates
            continue
        return True
    return False


def beam_directions(beams: int) -> tuple[np.ndarray, np.ndarray]:
    """Beam directions relative to the car: (cos, sin) of ``2 pi j / beams``, each ``(beams,)``."""
    ang = 2.0 * np.pi * np.arange(beams) / beams
    return np.cos(ang), np.sin(ang)


@nb.njit(cache=True)
def _scan_batch(town, x, y, yaw, beam_cos, beam_sin, boxes, origin, cell_start, cell_items, cell, gx, gy,
                max_range, out):
    nbeam = beam_cos.shape[0]
    inv_x, inv_y = np.empty(nbeam), np.empty(nbeam)
    for i in range(x.shape[0]):
        k = town[i]
        c = cell_of(x[i], y[i], origin[k, 0], origin[k, 1], cell, gx, gy)
        i0, i1 = (cell_start[k, c], cell_start[k, c + 1]) if c >= 0 else (0, 0)
        scan_into(x[i], y[i], yaw[i], beam_cos, beam_sin, boxes[k], cell_items[k], i0, i1, max_range,
                  inv_x, inv_y, out[i])


def lidar_scan(pack, town: np.ndarray, x: np.ndarray, y: np.ndarray, yaw: np.ndarray, beams: int,
               max_range: float) -> np.ndarray:
    """Ranges ``(B, beams)`` in metres for cars at (x, y, yaw) ``(B,)`` in towns ``town`` ``(B,)`` of a
    :class:`~shaped_es.envs.carnav.town.TownPack` (the scan the observation uses, for tests/rendering).
    ``max_range`` must not exceed the range the index was built for."""
    bc, bs = beam_directions(beams)
    out = np.empty((len(x), beams))
    gx, gy = pack.grid_shape
    _scan_batch(np.asarray(town, np.int64), np.asarray(x, np.float64), np.asarray(y, np.float64),
                np.asarray(yaw, np.float64), bc, bs, pack.boxes, pack.origin, pack.cell_start,
                pack.cell_items, pack.cell, gx, gy, float(max_range), out)
    return out
