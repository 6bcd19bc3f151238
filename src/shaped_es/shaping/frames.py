"""Which frame M_phi sees displacements in: the world's, or the agent's own direction of motion.

For a planar vehicle whose observation carries no absolute heading (CarNav-v0: heading *error*, body
velocities, lidar), a world-frame displacement ``position_{t+1} - position_t`` is ambiguous: the same
state and action move the car east or north depending on a yaw M_phi cannot see. Two frames remove that
ambiguity without any new key in the env contract (our additions, not the paper's, which used CARLA's
odometry; ``frame="world"`` is the paper's behaviour):

- ``motion``: the frame of the agent's last motion ``position_t - position_{t-1}`` (its heading, for a car
  without much slip). Undefined for an agent at rest (the angle of a zero step), which is where an ES
  population starts.
- ``waypoint``: the frame of the waypoint's direction ``waypoint_t - position_t``: x towards the
  waypoint, y to its left. Always defined (the waypoint is never where the agent is), and a query
  ``waypoint_t - position_t`` is ``(|w - p|, 0)`` in it: "straight to the waypoint"; what the agent's
  heading is relative to that direction, the model reads from the state (CarNav-v0: the heading error).

- ``both``: the world-frame displacement and the motion-frame one, concatenated (``2d`` inputs): the
  model picks whichever explains the action. A holonomic point's action lives in the world frame (a
  velocity command), a car's in its motion frame; measured closed loop (M_phi's labels driving the
  env, ``docs/shaped-results.md``) ``both`` matched the better single frame on a velocity point, a
  force point and CarNav-v0, where each single frame failed on one of them.

``motion`` and ``waypoint`` rotate the first two coordinates (planar); further coordinates stay as they are.
"""

from __future__ import annotations

import numpy as np

from shaped_es.data import Transitions

FRAMES = ("world", "motion", "waypoint", "both")


def frame_dim(frame: str, d: int) -> int:
    """Width of a ``d``-dimensional displacement expressed in ``frame`` (``both`` concatenates two)."""
    return 2 * d if frame == "both" else d


def last_step(tr: Transitions) -> np.ndarray:
    """``position_t - position_{t-1}`` ``(T, d)`` float64 within each episode (zero at an episode's first step)."""
    out = np.zeros(tr.position.shape, np.float64)
    if len(tr) > 1:
        same = (tr.episode[1:] == tr.episode[:-1]) & (tr.step[1:] == tr.step[:-1] + 1)  # (T-1,)
        out[1:] = np.where(same[:, None], tr.position[1:] - tr.position[:-1], 0.0)
    return out


def motion_angle(tr: Transitions) -> np.ndarray:
    """Angle ``(T,)`` of ``position_t - position_{t-1}`` within each episode (0 at an episode's first step)."""
    v = last_step(tr)  # (T, d)
    return np.arctan2(v[:, 1], v[:, 0]) if len(tr) else np.zeros(0)  # arctan2(0, 0) = 0 where it did not move


def waypoint_angle(tr: Transitions) -> np.ndarray:
    """Angle ``(T,)`` of ``waypoint_t - position_t`` in the plane of the first two coordinates."""
    d = (tr.waypoint[:, :2] - tr.position[:, :2]).astype(np.float64)  # (T, 2)
    return np.arctan2(d[:, 1], d[:, 0])


def to_frame(tr: Transitions, disp: np.ndarray, frame: str) -> np.ndarray:
    """Express displacements ``(T, d)`` of ``tr``'s steps in ``frame`` (planar: first two coordinates)."""
    if frame == "world":
        return disp
    if frame not in FRAMES:
        raise ValueError(f"frame must be one of {FRAMES}, got {frame!r}")
    if disp.shape[1] < 2:
        raise ValueError(f"frame={frame!r} needs positions with at least two coordinates")
    if frame == "both":
        return np.concatenate([disp, to_frame(tr, disp, "motion")], axis=1)  # (T, 2d)
    a = motion_angle(tr) if frame == "motion" else waypoint_angle(tr)
    return rotate(disp, a).astype(disp.dtype)


def rotate(disp: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """``disp`` ``(T, d)`` as float64 with its first two coordinates turned by ``-angle`` ``(T,)``: x along
    the angle's direction, y to its left (further coordinates as they are)."""
    c, s = np.cos(angle), np.sin(angle)
    out = disp.astype(np.float64, copy=True)
    out[:, 0] = c * disp[:, 0] + s * disp[:, 1]
    out[:, 1] = -s * disp[:, 0] + c * disp[:, 1]
    return out
