"""A hand-written waypoint follower for UR5Reach-v0: resolved-rate control toward ``info["waypoint"]``.

It proves the task solvable (tests) and gives reference actions. It uses the train-time contract
(``info["position"]``, ``info["waypoint"]``), which a test-time policy never sees (paper, Sec. III).

Desired flange velocity ``v = gain * (waypoint - position)``; joint velocities by damped least squares
``qd = J^T (J J^T + lambda^2 I)^-1 v`` with the DH Jacobian (``kinematics.py``); torques
``tau = damping * qd`` (with the core's joint damping and gravity compensation the arm then settles
at ``qd``), normalized by the torque limits and clipped to ``[-1, 1]``.
"""

from __future__ import annotations

import numpy as np

from shaped_es.envs.ur5.config import UR5Config
from shaped_es.envs.ur5.kinematics import world_jacobian


def waypoint_controller(config: UR5Config, obs: np.ndarray, position: np.ndarray, waypoint: np.ndarray,
                        gain: float = 10.0, damping_lambda: float = 0.05) -> np.ndarray:
    """Actions ``(B, 5)`` in ``[-1, 1]`` from ``obs`` ``(B, 13)`` and contract positions ``(B, 3)``."""
    q = np.asarray(obs, dtype=np.float64)[:, :5]  # (B, 5) joint angles
    v = gain * (np.asarray(waypoint) - np.asarray(position))  # (B, 3) desired flange velocity
    J = world_jacobian(q)  # (B, 3, 5)
    JJt = J @ np.swapaxes(J, 1, 2) + damping_lambda**2 * np.eye(3)  # (B, 3, 3)
    qd = (np.swapaxes(J, 1, 2) @ np.linalg.solve(JJt, v[..., None]))[..., 0]  # (B, 5)
    tau = np.asarray(config.joint_damping) * qd  # (B, 5)
    return np.clip(tau / np.asarray(config.torque_limits), -1.0, 1.0).astype(np.float32)
