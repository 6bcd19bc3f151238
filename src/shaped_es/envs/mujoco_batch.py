"""The batched MuJoCo plumbing ReacherWay-v0 and SwimmerWay-v0 share (``reacher.py``, ``swimmer.py``).

Both replay a Gymnasium MuJoCo env episode for episode: its model file from Gymnasium's assets, its
``reset_model`` draws from ``gymnasium.utils.seeding.np_random(seed)`` one episode at a time, and its
frame-skip stepping, run for ``B`` episodes at once in one ``mujoco.batch.Batch`` per batch size.
``MujocoBatchCore`` holds that; a subclass adds its state, observation, reward and controller.
"""

from __future__ import annotations

import os
from dataclasses import asdict
from typing import Any

import mujoco
import numpy as np
from gymnasium.utils import seeding
from mujoco import batch as mj_batch


def gym_asset(name: str) -> str:
    """Path of the model file ``name`` (e.g. ``"reacher.xml"``) in Gymnasium's MuJoCo assets, found without
    importing ``gymnasium.envs.mujoco`` (its ``__init__`` imports ``imageio``, an optional dependency
    that the batched cores do not need)."""
    import gymnasium

    return os.path.join(os.path.dirname(gymnasium.__file__), "envs", "mujoco", "assets", name)


class FrameSkipConfig:
    """Mixin of a frozen dataclass config with ``frame_skip`` (physics steps of 0.01 s per env step)."""

    frame_skip: int

    @property
    def dt(self) -> float:
        return 0.01 * self.frame_skip

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


class MujocoBatchCore:
    """A Gymnasium MuJoCo model stepped for ``B`` episodes at once. Subclasses set ``config_cls``,
    ``asset`` (the model file's name), ``obs_dim``/``act_dim``/``pos_dim``, ``bind_outputs`` (the
    outputs each batch must fill) and ``draw_reset`` (one episode's reset draws)."""

    config_cls: type
    asset: str
    obs_dim: int
    act_dim: int
    pos_dim: int
    bind_outputs: tuple[str, ...] = ()

    def __init__(self, config=None):
        self.config = (config or self.config_cls()).validate()
        self.max_steps = self.config.max_steps
        self.model = mujoco.MjModel.from_xml_path(gym_asset(self.asset))
        self._batches: dict[int, mj_batch.Batch] = {}

    def _batch(self, n: int) -> mj_batch.Batch:
        if n not in self._batches:
            b = mj_batch.Batch(self.model, n, nthread=self.config.threads)
            for name in self.bind_outputs:
                b.bind(name)  # outputs are filled only once bound
            self._batches[n] = b
        return self._batches[n]

    def draw_reset(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """One episode's ``(qpos (nq,), qvel (nv,))`` drawn from ``rng`` as the Gymnasium env's
        ``reset_model`` draws them."""
        raise NotImplementedError

    def reset_joints(self, seeds: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(qpos (B, nq), qvel (B, nv))`` of the episodes ``seeds``, one ``np_random(seed)`` each."""
        seeds = np.asarray(seeds, dtype=np.int64).reshape(-1)
        B, m = seeds.shape[0], self.model
        qpos, qvel = np.empty((B, m.nq)), np.empty((B, m.nv))
        for i, s in enumerate(seeds):
            qpos[i], qvel[i] = self.draw_reset(seeding.np_random(int(s))[0])
        return qpos, qvel

    def clip_action(self, action: np.ndarray, B: int) -> np.ndarray:
        """``action`` as ``(B, act_dim)`` float64 clipped to ``[-1, 1]``."""
        return np.clip(np.asarray(action, dtype=np.float64).reshape(B, self.act_dim), -1.0, 1.0)

    def advance(self, state, act: np.ndarray, record: str | None = None):
        """``frame_skip`` physics steps of ``act`` ``(B, act_dim)`` from ``state.qpos``/``state.qvel`` for
        the episodes not ``state.done``; ended ones stay as they were. Returns ``(alive, qpos, qvel,
        last)``: ``last`` is the output ``record`` (a bound name) at the start of the last substep,
        ``(B, ...)`` (zeros for ended episodes), or None without ``record``."""
        B = state.batch_size
        alive = ~state.done
        b = self._batch(B)
        b.bind("qpos")[:], b.bind("qvel")[:], b.bind("ctrl")[:] = state.qpos, state.qvel, act
        ids = None if alive.all() else np.flatnonzero(alive)
        last = None if record is None else np.zeros((B, *b.bind(record).shape[1:]))
        if ids is None or ids.size:
            rec = b.rollout(self.config.frame_skip, record=() if record is None else (record,), ids=ids)
            if record is not None:
                last[alive if ids is not None else slice(None)] = rec[record][:, -1]  # (n, ...)
        qpos = np.where(alive[:, None], b.bind("qpos"), state.qpos)  # (B, nq)
        qvel = np.where(alive[:, None], b.bind("qvel"), state.qvel)  # (B, nv)
        return alive, qpos, qvel, last
