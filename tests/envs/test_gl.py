"""``envs/gl.py``: MuJoCo's OpenGL backend picked where nothing chose one."""

import os
import sys

from shaped_es.envs.gl import headless_gl


def test_headless_gl_picks_egl_only_where_nothing_chose_a_backend(monkeypatch):
    monkeypatch.delitem(sys.modules, "mujoco", raising=False)
    for var in ("MUJOCO_GL", "DISPLAY", "WAYLAND_DISPLAY"):
        monkeypatch.delenv(var, raising=False)
    headless_gl()
    assert os.environ["MUJOCO_GL"] == "egl"
    monkeypatch.setenv("MUJOCO_GL", "osmesa")  # the user's choice stays
    headless_gl()
    assert os.environ["MUJOCO_GL"] == "osmesa"
    monkeypatch.delenv("MUJOCO_GL")
    monkeypatch.setenv("DISPLAY", ":0")  # a display: GLFW works, nothing set
    headless_gl()
    assert "MUJOCO_GL" not in os.environ
