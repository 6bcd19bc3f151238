"""Forward kinematics of the UR5 from its published Denavit-Hartenberg parameters (Universal Robots).

Standard DH convention: the transform from frame ``i`` to frame ``i-1`` is
``T_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``; the tool flange is the origin of frame 6. The MJCF
model ``ur5.xml`` nests its bodies exactly on these frames, so its ``ee`` site must coincide with
:func:`fk_position` (checked by the tests to well under 1 mm). The env's sixth joint is fixed at
``theta_6 = 0``; it does not move the flange origin anyway.
"""

from __future__ import annotations

import numpy as np

# Published UR5 DH parameters (metres, radians), joints 1..6.
DH_D = np.array([0.089159, 0.0, 0.0, 0.10915, 0.09465, 0.0823])
DH_A = np.array([0.0, -0.425, -0.39225, 0.0, 0.0, 0.0])
DH_ALPHA = np.array([np.pi / 2, 0.0, 0.0, np.pi / 2, -np.pi / 2, 0.0])
# The arm is mounted like ROS's base_link: the DH base frame is turned by pi about world z.
WORLD_FROM_BASE = np.diag([-1.0, -1.0, 1.0])


def dh_transforms(q: np.ndarray) -> np.ndarray:
    """Per-joint DH transforms ``T_i`` for joint angles ``q`` ``(..., k)``, k <= 6 (missing joints = 0).

    Returns ``(..., 6, 4, 4)``.
    """
    q = np.asarray(q, dtype=np.float64)
    theta = np.zeros(q.shape[:-1] + (6,))  # (..., 6)
    theta[..., : q.shape[-1]] = q
    ct, st = np.cos(theta), np.sin(theta)  # (..., 6)
    ca, sa = np.cos(DH_ALPHA), np.sin(DH_ALPHA)  # (6,)
    T = np.zeros(theta.shape + (4, 4))  # (..., 6, 4, 4)
    T[..., 0, 0], T[..., 0, 1], T[..., 0, 2], T[..., 0, 3] = ct, -st * ca, st * sa, DH_A * ct
    T[..., 1, 0], T[..., 1, 1], T[..., 1, 2], T[..., 1, 3] = st, ct * ca, -ct * sa, DH_A * st
    T[..., 2, 1], T[..., 2, 2], T[..., 2, 3] = sa, ca, DH_D
    T[..., 3, 3] = 1.0
    return T


def fk_frames(q: np.ndarray) -> np.ndarray:
    """Base-frame poses of DH frames 0..6, ``(..., 7, 4, 4)`` (frame 0 is the identity)."""
    T = dh_transforms(q)  # (..., 6, 4, 4)
    out = np.zeros(T.shape[:-3] + (7, 4, 4))  # (..., 7, 4, 4)
    out[..., 0, :, :] = np.eye(4)
    for i in range(6):
        out[..., i + 1, :, :] = out[..., i, :, :] @ T[..., i, :, :]
    return out


def fk_position(q: np.ndarray) -> np.ndarray:
    """Tool-flange position (origin of DH frame 6) in the base frame, ``(..., 3)``."""
    return fk_frames(q)[..., 6, :3, 3]


def world_position(q: np.ndarray) -> np.ndarray:
    """Tool-flange position in the world frame of ``ur5.xml``, ``(..., 3)``."""
    return fk_position(q) @ WORLD_FROM_BASE.T


def world_jacobian(q: np.ndarray) -> np.ndarray:
    """Positional Jacobian ``d p_world / d q`` of the flange for the ``k`` given joints, ``(..., 3, k)``.

    Revolute joint ``i`` turns about ``z_{i-1}`` through ``o_{i-1}``: column ``z_{i-1} x (p - o_{i-1})``.
    """
    q = np.asarray(q, dtype=np.float64)
    F = fk_frames(q)  # (..., 7, 4, 4)
    k = q.shape[-1]
    z = F[..., :k, :3, 2]  # (..., k, 3) joint axes
    o = F[..., :k, :3, 3]  # (..., k, 3) joint origins
    p = F[..., 6:7, :3, 3]  # (..., 1, 3) flange
    cols = np.cross(z, p - o) @ WORLD_FROM_BASE.T  # (..., k, 3)
    return np.swapaxes(cols, -1, -2)  # (..., 3, k)
