"""Which frame M_phi sees displacements in: the world's, or the agent's own direction of motion.

For a planar vehicle whose observation carries no absolute heading (CarNav-v0: heading *error*, body
velocities, lidar), a world-frame displacement ``position_{t+1} - position_t`` is ambiguous: the same
state and action move the car east or north depending on a yaw M_phi cannot see. Expressing every
displacement in the frame of the agent's last motion ``position_t - position_{t-1}`` (its heading, for a
car without much slip) removes that ambiguity without any new key in the env contract. This is our
addition, not the paper's (which used CARLA's odometry); ``frame="world"`` is the paper's behaviour.
"""

from __future__ import annotations

import numpy as np

from shaped_es.data import Transitions

FRAMES = ("world", "motion")


def motion_angle(tr: Transitions) -> np.ndarray:
    """Angle ``(T,)`` of ``position_t - position_{t-1}`` within each episode (0 at an episode's first step)."""
    ang = np.zeros(len(tr), dtype=np.float64)
    if len(tr) < 2:
        return ang
    prev_same = (tr.episode[1:] == tr.episode[:-1]) & (tr.step[1:] == tr.step[:-1] + 1)  # (T-1,)
    d = (tr.position[1:, :2] - tr.position[:-1, :2]).astype(np.float64)  # (T-1, 2)
    ang[1:] = np.where(prev_same, np.arctan2(d[:, 1], d[:, 0]), 0.0)
    return ang


def to_frame(tr: Transitions, disp: np.ndarray, frame: str) -> np.ndarray:
    """Express displacements ``(T, d)`` of ``tr``'s steps in ``frame`` (planar: first two coordinates)."""
    if frame == "world":
        return disp
    if frame != "motion":
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    if disp.shape[1] < 2:
        raise ValueError("frame='motion' needs positions with at least two coordinates")
    a = motion_angle(tr)
    c, s = np.cos(a), np.sin(a)
    out = disp.astype(np.float64, copy=True)
    out[:, 0] = c * disp[:, 0] + s * disp[:, 1]  # rotate by -angle: x along the motion
    out[:, 1] = -s * disp[:, 0] + c * disp[:, 1]  # y to its left
    return out.astype(disp.dtype)
