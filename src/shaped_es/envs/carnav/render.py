"""Top-down ``rgb_array`` frames of CarNav-v0 (NumPy + Pillow; no display needed).

Shows the roads, obstacles, the planner's route, the global waypoints (grey once passed), the next
global waypoint (green), the local waypoint (red), the lidar rays (yellow) and the car (white, heading
marked in red). The view is ``render_window`` metres around the car, or the whole town if it is 0.
"""

from __future__ import annotations

import numpy as np
from PIL import Image, ImageDraw

from shaped_es.envs.carnav.lidar import lidar_scan

_GRASS, _ROAD, _BOX, _ROUTE = (58, 94, 58), (90, 90, 96), (176, 150, 118), (70, 120, 230)


def render_top_down(core, state, i: int = 0) -> np.ndarray:
    """Frame ``(S, S, 3)`` uint8 of car ``i`` of a :class:`~shaped_es.envs.carnav.core.CarNavCore` state."""
    cfg, pack = core.config, core.pack
    k = int(state.town[i])
    town = pack.towns[k]
    size, cx, cy, yaw = cfg.render_size, float(state.x[i]), float(state.y[i]), float(state.yaw[i])
    if cfg.render_window > 0:
        half = cfg.render_window / 2
        x0, y0, span = cx - half, cy - half, cfg.render_window
    else:
        x0, y0 = town.extent[0], town.extent[1]
        span = float(max(town.extent[2] - town.extent[0], town.extent[3] - town.extent[1]))
    scale = size / span

    def px(pts) -> list[tuple[float, float]]:
        pts = np.asarray(pts, dtype=np.float64).reshape(-1, 2)  # (n, 2) metres -> pixels, y up
        return [((p[0] - x0) * scale, size - (p[1] - y0) * scale) for p in pts]

    def rect(x_lo, y_lo, x_hi, y_hi):
        (a, b), (c, d) = px([[x_lo, y_hi], [x_hi, y_lo]])
        return [a, b, max(a, c), max(b, d)]

    img = Image.new("RGB", (size, size), _GRASS)
    draw = ImageDraw.Draw(img)
    hw = cfg.road_width / 2
    for a, b in town.edges:  # open roads
        lo = np.minimum(town.nodes[a], town.nodes[b]) - hw  # (2,) road rectangle corners
        hi = np.maximum(town.nodes[a], town.nodes[b]) + hw
        draw.rectangle(rect(lo[0], lo[1], hi[0], hi[1]), fill=_ROAD)
    for bx0, by0, bx1, by1 in town.boxes:
        draw.rectangle(rect(bx0, by0, bx1, by1), fill=_BOX, outline=(120, 100, 80))
    n = int(state.n_dense[i])
    route = state.route[i, :n]  # (n, 2)
    draw.line(px(route), fill=_ROUTE, width=max(1, int(0.4 * scale)))
    wps = state.route_waypoints(i, cfg.wp_stride)  # (H, 2)
    r = max(1.5, 0.25 * scale)
    next_k = int(state.k[i])
    for j, (u, v) in enumerate(px(wps)):
        color = (150, 150, 150) if j + 1 < next_k else (120, 220, 255)
        draw.ellipse([u - r, v - r, u + r, v + r], fill=color)
    ranges = lidar_scan(pack, state.town[i:i + 1], state.x[i:i + 1], state.y[i:i + 1], state.yaw[i:i + 1],
                        cfg.lidar_beams, cfg.lidar_range)[0]  # (beams,)
    ang = yaw + 2 * np.pi * np.arange(cfg.lidar_beams) / cfg.lidar_beams
    hits = np.stack([cx + ranges * np.cos(ang), cy + ranges * np.sin(ang)], axis=1)  # (beams, 2)
    (ou, ov), = px([cx, cy])
    for u, v in px(hits):
        draw.line([(ou, ov), (u, v)], fill=(240, 220, 60), width=1)
    if next_k <= len(wps):
        (u, v), = px(wps[next_k - 1])
        draw.ellipse([u - 2 * r, v - 2 * r, u + 2 * r, v + 2 * r], outline=(60, 230, 60), width=2)
    (u, v), = px(state.route[i, int(state.local[i])])
    draw.ellipse([u - 1.5 * r, v - 1.5 * r, u + 1.5 * r, v + 1.5 * r], fill=(230, 50, 50))
    c, s = np.cos(yaw), np.sin(yaw)
    hl, hwid = cfg.car_length / 2, cfg.car_width / 2
    corners = [(cx + c * a - s * b, cy + s * a + c * b) for a, b in ((hl, hwid), (-hl, hwid), (-hl, -hwid),
                                                                      (hl, -hwid))]
    draw.polygon(px(corners), fill=(245, 245, 245), outline=(20, 20, 20))
    draw.line(px([[cx, cy], [cx + c * hl, cy + s * hl]]), fill=(220, 30, 30), width=max(1, int(0.3 * scale)))
    return np.asarray(img, dtype=np.uint8)
