"""UR5Reach-v0 rendering: rgb_array frames where an OpenGL backend exists, one clear error where not."""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from shaped_es.envs.ur5.env import UR5ReachEnv
from shaped_es.envs.ur5.render import RenderUnavailableError, UR5Renderer

SRC = str(Path(__file__).resolve().parents[2] / "src")


def test_rgb_array_render_shows_arm_target_and_waypoints():
    env = UR5ReachEnv(render_mode="rgb_array", width=160, height=120)
    env.reset(seed=0)
    try:
        frame = env.render()
    except RenderUnavailableError as err:
        pytest.skip(f"no OpenGL backend here: {err}")
    assert frame.shape == (120, 160, 3) and frame.dtype == np.uint8
    assert frame.std() > 10  # not a blank image
    blue = (frame[..., 2] > 180) & (frame[..., 0] < 90)  # the target sphere
    red = (frame[..., 0] > 160) & (frame[..., 1] < 60) & (frame[..., 2] < 60)  # the waypoints
    assert blue.any() and red.any()
    env.step(np.full(5, 0.5, np.float32))
    assert not np.array_equal(env.render(), frame)  # the arm moved
    env.close()


def test_missing_backend_raises_one_line_error(monkeypatch):
    import mujoco

    def broken(*args, **kwargs):
        raise mujoco.FatalError("an OpenGL platform library has not been loaded into this process")

    monkeypatch.setattr(mujoco, "Renderer", broken)
    with pytest.raises(RenderUnavailableError) as err:
        UR5Renderer(UR5ReachEnv().batch_core.model)
    msg = str(err.value)
    assert "\n" not in msg and "MUJOCO_GL=egl" in msg and "libegl1" in msg and "FatalError" in msg


def test_disabled_gl_backend_gives_the_clear_error_in_a_fresh_process():
    code = (
        "from shaped_es.envs.ur5.env import UR5ReachEnv\n"
        "from shaped_es.envs.ur5.render import RenderUnavailableError\n"
        "env = UR5ReachEnv(render_mode='rgb_array'); env.reset(seed=0)\n"
        "try:\n    env.render()\nexcept RenderUnavailableError as e:\n    print('CLEAR', e)\n"
    )
    env = {**os.environ, "MUJOCO_GL": "disable", "PYTHONPATH": SRC}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert len(lines) == 1
    assert lines[0].startswith("CLEAR offscreen rendering needs OpenGL (MUJOCO_GL=disable)")
