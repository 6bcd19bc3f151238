"""MuJoCo's OpenGL backend where nothing chose one: ``MUJOCO_GL`` is read once, when ``mujoco`` is imported, and its
default (GLFW) needs a display. :func:`headless_gl` picks ``egl`` (headless; apt packages ``libegl1
libgl1-mesa-dri``) where ``MUJOCO_GL`` is unset, there is no display and ``mujoco`` is not imported yet; a backend
the user set is kept. UR5Reach-v0's package calls it on import, ``render`` and a run with ``video_every`` before an
own env's module imports ``mujoco`` (a new user's headless render of a MuJoCo arm ended in an internal
``FatalError``)."""

from __future__ import annotations

import os
import sys


def headless_gl() -> None:
    if "mujoco" in sys.modules or os.environ.get("MUJOCO_GL", "").strip():
        return
    if not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
        os.environ["MUJOCO_GL"] = "egl"
