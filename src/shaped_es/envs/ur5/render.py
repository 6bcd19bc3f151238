"""Offscreen ``rgb_array`` frames of UR5Reach-v0 through MuJoCo's renderer (cf. the paper's Fig. 1b: the
target in blue, the Bezier waypoints in red).

Rendering needs an OpenGL backend chosen by ``MUJOCO_GL`` *before* ``mujoco`` is imported: ``egl``
(headless; Debian/Ubuntu packages ``libegl1 libgl1-mesa-dri``: EGL plus Mesa's software driver) or
``osmesa`` (``libosmesa6``). Importing ``shaped_es.envs.ur5`` picks ``egl`` when ``MUJOCO_GL`` is unset,
there is no display and ``mujoco`` is not imported yet. Without a working backend, :class:`UR5Renderer`
raises :class:`RenderUnavailableError` with a one-line message.
"""

from __future__ import annotations

import copy
import os

import mujoco
import numpy as np

TARGET_RGBA = np.array([0.1, 0.3, 1.0, 1.0], dtype=np.float32)  # blue target (paper, Fig. 1b)
WAYPOINT_RGBA = np.array([0.9, 0.1, 0.1, 0.8], dtype=np.float32)  # red waypoints
NEXT_RGBA = np.array([1.0, 0.8, 0.0, 1.0], dtype=np.float32)  # the next waypoint


class RenderUnavailableError(RuntimeError):
    """No OpenGL backend for offscreen rendering; the message says how to get one."""


def _hint(reason: str) -> str:
    backend = os.environ.get("MUJOCO_GL", "") or "unset"
    return (f"offscreen rendering needs OpenGL (MUJOCO_GL={backend}): set MUJOCO_GL=egl "
            "(apt-get install libegl1 libgl1-mesa-dri) or MUJOCO_GL=osmesa (apt-get install libosmesa6) "
            f"before importing mujoco [{reason}]")


class UR5Renderer:
    """Renders one arm pose with its target and waypoints; owns a private copy of the model."""

    def __init__(self, model: mujoco.MjModel, width: int = 480, height: int = 360,
                 lookat=(0.2, 0.15, 0.3), distance: float = 1.6, azimuth: float = 150.0,
                 elevation: float = -25.0):
        self.model = copy.copy(model)  # the target site moves per frame: never touch the core's model
        self.model.vis.global_.offwidth = max(width, self.model.vis.global_.offwidth)
        self.model.vis.global_.offheight = max(height, self.model.vis.global_.offheight)
        self.data = mujoco.MjData(self.model)
        try:
            self._renderer = mujoco.Renderer(self.model, height, width)
        except Exception as exc:  # any backend failure: ImportError, FatalError, EGL errors, ...
            reason = (str(exc).strip().splitlines() or [type(exc).__name__])[0]
            raise RenderUnavailableError(_hint(f"{type(exc).__name__}: {reason}")) from None
        self.camera = mujoco.MjvCamera()
        self.camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        self.camera.lookat[:] = lookat
        self.camera.distance, self.camera.azimuth, self.camera.elevation = distance, azimuth, elevation
        self._target_site = self.model.site("target").id

    def _add_sphere(self, pos: np.ndarray, radius: float, rgba: np.ndarray) -> None:
        scene = self._renderer.scene
        if scene.ngeom >= scene.maxgeom:
            return
        mujoco.mjv_initGeom(scene.geoms[scene.ngeom], mujoco.mjtGeom.mjGEOM_SPHERE,
                            np.array([radius, 0.0, 0.0]), np.asarray(pos, dtype=np.float64),
                            np.eye(3).reshape(-1), rgba)
        scene.ngeom += 1

    def render(self, qpos: np.ndarray, target: np.ndarray, waypoints: np.ndarray | None = None,
               next_index: int | None = None) -> np.ndarray:
        """Frame ``(height, width, 3)`` uint8 of joint angles ``qpos`` ``(5,)``; ``waypoints`` ``(H, 3)``."""
        self.data.qpos[:] = qpos
        self.model.site_pos[self._target_site] = target
        mujoco.mj_forward(self.model, self.data)
        self._renderer.update_scene(self.data, self.camera)
        if waypoints is not None:
            for k, w in enumerate(waypoints):
                self._add_sphere(w, 0.012 if k == next_index else 0.006,
                                 NEXT_RGBA if k == next_index else WAYPOINT_RGBA)
        return self._renderer.render()

    def close(self) -> None:
        self._renderer.close()
