"""Write a rollout of a run's trained policy as an animated GIF (``shaped-es render RUN --out video.gif``).

The policy is the checkpoint's best one (``policy/best``: the member with the best test reward; PPO: its
best weights), or ``mean`` for the latest search mean / PPO weights. Frames come from
``env.render()`` with ``render_mode="rgb_array"`` (headless) and are written with Pillow. Episode seeds
are drawn as ``evaluate`` draws them (a seed outside every training and test stream).

Gymnasium's classic-control envs (CartPole, Pendulum, ...) draw their frames with pygame, which is not a
dependency of the package: ``pip install -e ".[render]"`` brings it (without it, rendering one fails in
one line naming that extra). The built-in envs and MuJoCo ones render without pygame.
"""

from __future__ import annotations

import io
from pathlib import Path

import gymnasium as gym
import numpy as np

from shaped_es import seeding
from shaped_es.config import check_seed
from shaped_es.env_probe import reward as one_reward
from shaped_es.rollout import DEFAULT_MAX_STEPS, EnvSpecError, close_env, env_time_limit, make_env
from shaped_es.rundir.atomic import atomic_write_bytes
from shaped_es.rundir.store import RunStore, StoreError
from shaped_es.trained.load import load_policy


def _rgb_env(env_id: str, env_kwargs: dict) -> gym.Env:
    probe = make_env(env_id, env_kwargs)
    modes = probe.metadata.get("render_modes") or []
    close_env(probe)
    if "rgb_array" not in modes:
        raise EnvSpecError(f"env {env_id!r} cannot render rgb_array frames (render modes: {modes}); an env renders "
                           f"with 'rgb_array' in metadata['render_modes'] and a render() that returns an (H, W, 3) "
                           f"uint8 array (README: your own env)")
    try:
        return make_env(env_id, {**env_kwargs, "render_mode": "rgb_array"})
    except EnvSpecError as exc:
        raise EnvSpecError(f"env {env_id!r} cannot render rgb_array frames: {exc}") from None


RENDER_EXTRA_HINT = 'pip install -e ".[render]" (or pip install "shaped-es[render]")'


def _missing_pygame(exc: BaseException) -> bool:
    """True if ``exc`` (or what caused it) is pygame failing to import (gymnasium raises
    ``DependencyNotInstalled`` from the ``ImportError``)."""
    seen = 0
    while exc is not None and seen < 5:
        if isinstance(exc, ImportError) and (exc.name or "").split(".")[0] == "pygame":
            return True
        if isinstance(exc, (ImportError, gym.error.DependencyNotInstalled)) and "pygame" in str(exc):
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


def _frame(env, env_id: str) -> np.ndarray:
    try:
        frame = env.render()
    except Exception as exc:  # noqa: BLE001 - e.g. no pygame / OpenGL (MuJoCo's own FatalError, not a RuntimeError)
        renderer = (gym.error.Error, ImportError, RuntimeError, OSError, ValueError)
        if not isinstance(exc, renderer) and type(exc).__module__.split(".")[0] != "mujoco":
            raise
        if _missing_pygame(exc):
            raise EnvSpecError(f"env {env_id!r} renders with pygame, which is not installed: "
                               f"{RENDER_EXTRA_HINT}") from None
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise EnvSpecError(f"env {env_id!r} cannot render rgb_array frames: {msg}{_gl_hint(msg)}") from None
    frame = None if frame is None else np.asarray(frame)
    if frame is None or frame.ndim != 3 or frame.shape[2] not in (3, 4):
        raise EnvSpecError(f"env {env_id!r} cannot render rgb_array frames (render() gave "
                           f"{None if frame is None else frame.shape})")
    return frame[..., :3].astype(np.uint8)


def _gl_hint(msg: str) -> str:
    """Where MuJoCo found no OpenGL (a machine without a display: a new user's headless render of a MuJoCo arm ended
    in an internal FatalError), how to give it one."""
    if not any(k in msg for k in ("OpenGL", "GLFW", "EGL", "gladLoadGL", "mjr_makeContext")):
        return ""
    return "; on a machine without a display set MUJOCO_GL=egl (or osmesa) in the environment"


def check_renders(env_id: str, env_kwargs: dict) -> None:
    """``EnvSpecError`` (one line) unless the env renders an ``rgb_array`` frame after ``reset``."""
    env = _rgb_env(env_id, env_kwargs)
    try:
        env.reset(seed=0)
        _frame(env, env_id)
    finally:
        env.close()


def render_run(run_dir: str | Path, out: str | Path, episodes: int = 1, which: str = "best",
               seed: int = 12345, max_steps: int | None = None, fps: float | None = None, every: int = 1) -> dict:
    """Roll out the run's policy for ``episodes`` episodes and write every ``every``-th frame to ``out``; ``fps``
    None: the env's ``metadata['render_fps']`` over ``every`` (real time; a new user's 6 s episode played in 2 s at a
    fixed 30), else 30."""
    if episodes <= 0 or every <= 0 or (fps is not None and fps <= 0) or (max_steps is not None and max_steps <= 0):
        raise StoreError("--episodes, --every, --fps and --max-steps must be positive")
    out = Path(out)
    if out.suffix.lower() != ".gif":
        raise StoreError(f"--out must name a .gif file, got {out}")
    check_seed(seed)
    cfg = RunStore(run_dir).read_config()
    act = load_policy(run_dir, which).predict  # evaluate's actions, any method
    env = _rgb_env(cfg.env, cfg.env_kwargs)
    cap = max_steps or cfg.rollout.max_steps or (None if env_time_limit(env) else DEFAULT_MAX_STEPS)
    seeds = seeding.evaluation_seeds(episodes, seed)  # evaluate's episodes
    frames, returns = [], []
    try:
        for s in seeds:
            obs, _ = env.reset(seed=int(s))
            frames.append(_frame(env, cfg.env))
            total, t, done = 0.0, 0, False
            while not done and (cap is None or t < cap):
                obs, r, term, trunc, _ = env.step(act(np.asarray(obs, dtype=np.float32)))
                total, t, done = total + one_reward(r), t + 1, term or trunc
                if t % every == 0 or done:
                    frames.append(_frame(env, cfg.env))
            returns.append(total)
    finally:
        close_env(env)
    if fps is None:
        native = (getattr(env, "metadata", None) or {}).get("render_fps")
        fps = float(native) / every if isinstance(native, (int, float)) and native > 0 else 30.0
    _write_gif(frames, out, fps)
    return {"run_dir": str(run_dir), "out": str(out), "policy": which, "episodes": episodes,
            "frames": len(frames), "fps": fps, "returns": returns}


def _write_gif(frames: list[np.ndarray], out: Path, fps: float) -> None:
    from PIL import Image

    images = [Image.fromarray(f) for f in frames]
    buf = io.BytesIO()
    images[0].save(buf, format="GIF", save_all=True, append_images=images[1:],
                   duration=max(20, int(round(1000.0 / fps))), loop=0)
    # a temporary of its own (mkstemp), then a rename: a fixed .NAME.tmp wrote over a user's file of that name,
    # or through a symlink of that name out of the folder
    atomic_write_bytes(out, buf.getvalue())
