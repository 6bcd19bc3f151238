"""``render``: a GIF of a run's best policy (ES and PPO), and one clear error for envs that cannot render."""

import argparse
import json
import sys

import gymnasium as gym
import numpy as np
import pytest
from helpers import train
from PIL import Image

from shaped_es.baselines.ppo_settings import PPOSettings
from shaped_es.cli.commands import add_render_parser
from shaped_es.config import build_config
from shaped_es.rollout import EnvSpecError
from shaped_es.rundir.store import StoreError


class DotEnv(gym.Env):
    """A point moving on a line; rgb frames drawn with NumPy (no pygame), 12 steps per episode."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 30}

    def __init__(self, render_mode=None):
        self.render_mode = render_mode
        self.observation_space = gym.spaces.Box(-10, 10, (2,), np.float32)
        self.action_space = gym.spaces.Box(-1, 1, (1,), np.float32)
        self.x, self.t = 0.0, 0

    def reset(self, seed=None, options=None):
        super().reset(seed=seed)
        self.x, self.t = float(self.np_random.uniform(-1, 1)), 0
        return np.array([self.x, 0.0], np.float32), {}

    def step(self, a):
        self.x, self.t = self.x + float(a[0]), self.t + 1
        return np.array([self.x, self.t], np.float32), -abs(self.x), False, self.t >= 12, {}

    def render(self):
        img = np.zeros((16, 32, 3), np.uint8)
        img[:, int(np.clip(16 + self.x, 0, 31))] = 255
        return img


class BlindEnv(DotEnv):
    """Declares no render modes."""

    metadata = {"render_modes": []}


class NoFrameEnv(DotEnv):
    """Claims rgb_array but returns no frame."""

    def render(self):
        return None


gym.register("DotRender-v0", entry_point=DotEnv)
gym.register("BlindRender-v0", entry_point=BlindEnv)
gym.register("NoFrame-v0", entry_point=NoFrameEnv)


def _run(tmp_path, env, method="vanilla", **over):
    cfg = build_config({"env": env, "method": method, "generations": 1, "seed": 0, "executor": "inline",
                        "es": {"pairs": 2}, "policy": {"hidden": [4]}, "tensorboard": False,
                        "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40}, **over})
    return train(tmp_path / f"{method}_{env}", cfg, ppo=PPOSettings(n_steps=64, batch_size=32, n_epochs=1)).root


def _cli(*argv):
    p = argparse.ArgumentParser()
    add_render_parser(p.add_subparsers(dest="command"))
    a = p.parse_args(["render", *map(str, argv)])
    return a.fn(a)


def test_render_gif_of_the_best_policy(tmp_path, capsys):
    run = _run(tmp_path, "DotRender-v0")
    out = tmp_path / "v" / "video.gif"
    assert _cli(run, "--out", out, "--episodes", "2") == 0
    res = json.loads(capsys.readouterr().out)
    assert res["frames"] == 2 * 13  # reset frame + 12 steps, per episode
    assert len(res["returns"]) == 2 and all(r < 0 for r in res["returns"])
    with Image.open(out) as im:
        assert im.format == "GIF" and im.n_frames >= 2 and im.size == (32, 16)
    assert res["fps"] == 30.0  # the env's render_fps: real time (a new user's 6 s episode played in 2 s at 30)
    assert _cli(run, "--out", tmp_path / "half.gif", "--every", "4") == 0
    half = json.loads(capsys.readouterr().out)
    assert half["frames"] == 1 + 3 and half["fps"] == 7.5  # t = 4, 8, 12; every 4th frame of 30 a second
    assert _cli(run, "--out", tmp_path / "fast.gif", "--fps", "50") == 0
    assert json.loads(capsys.readouterr().out)["fps"] == 50.0
    # its temporary is a file of its own: a user's .vid2.gif.tmp (the fixed name it used) stays as it was
    mine = tmp_path / ".vid2.gif.tmp"
    mine.write_text("mine")
    assert _cli(run, "--out", tmp_path / "vid2.gif") == 0
    assert mine.read_text() == "mine" and (tmp_path / "vid2.gif").stat().st_size > 0


@pytest.mark.parametrize("env", ["BlindRender-v0", "NoFrame-v0"])
def test_render_errors_are_one_line(tmp_path, env):
    run = _run(tmp_path, env)
    with pytest.raises(EnvSpecError, match="cannot render rgb_array frames"):
        _cli(run, "--out", tmp_path / "v.gif")
    with pytest.raises(StoreError, match=".gif"):
        _cli(run, "--out", tmp_path / "v.mp4")
    with pytest.raises(StoreError, match="not a run directory"):
        _cli(tmp_path / "nothing", "--out", tmp_path / "v.gif")


@pytest.mark.parametrize("method", ["vanilla", "ppo"])
def test_render_cartpole_headless(tmp_path, method):
    pytest.importorskip("pygame", reason="CartPole's renderer needs pygame (gymnasium[classic-control])")
    run = _run(tmp_path, "CartPole-v1", method=method)
    out = tmp_path / "cartpole.gif"
    assert _cli(run, "--out", out, "--max-steps", "30") == 0
    with Image.open(out) as im:
        assert im.size == (600, 400) and im.n_frames >= 2


def test_render_classic_control_without_pygame_names_the_render_extra(tmp_path, monkeypatch, capsys):
    from shaped_es.cli.commands import main

    run = _run(tmp_path, "CartPole-v1")
    monkeypatch.setitem(sys.modules, "pygame", None)  # import pygame -> ImportError, as if not installed
    monkeypatch.setitem(sys.modules, "pygame.gfxdraw", None)
    with pytest.raises(EnvSpecError, match=r"pygame, which is not installed: pip install -e \".\[render\]\""):
        _cli(run, "--out", tmp_path / "v.gif")
    capsys.readouterr()
    assert main(["render", str(run), "--out", str(tmp_path / "v.gif")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("shaped-es: error:") and "\n" not in err and ".[render]" in err, err
    assert not (tmp_path / "v.gif").exists()


def test_mujoco_without_opengl_is_one_line_naming_mujoco_gl():
    """A new user's headless render of a MuJoCo arm ended in an internal ``FatalError`` (MuJoCo's own exception, not
    a RuntimeError): it is one line now, saying how to give MuJoCo an OpenGL."""
    from shaped_es.rollout import EnvSpecError
    from shaped_es.trained.render import _frame

    FatalError = type("FatalError", (Exception,), {"__module__": "mujoco"})

    class NoGL:
        def render(self):
            raise FatalError("an OpenGL platform library has not been loaded into this process")

    with pytest.raises(EnvSpecError, match="set MUJOCO_GL=egl"):
        _frame(NoGL(), "Arm-v0")

    class Broken:  # any other exception is the env's own bug: not swallowed
        def render(self):
            raise KeyError("x")

    with pytest.raises(KeyError):
        _frame(Broken(), "Arm-v0")
