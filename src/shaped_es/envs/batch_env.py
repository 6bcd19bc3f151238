"""``BatchCoreEnv``: the thin Gymnasium ``Env`` over a batched core (``envs/core.py``) with B = 1.

Every built-in env is this class over its own core and config; only the Gymnasium-style docstring
(spaces, rewards, arguments) and the renderer are the env's own (``carnav/env.py``, ``ur5/env.py``).

Each env module registers two entry points: ``make_limited = limited_entry_point(Env)`` (``envs/core.py``:
the env under a ``TimeLimit`` of its config's ``max_steps``, so ``env.spec.max_episode_steps`` is the
horizon of whatever preset and overrides were asked for) and, for ``gymnasium.make_vec``,
``<Name>VectorEnv = vector_entry_point(Env)`` (``envs/vector.py``: the batched core as a ``VectorEnv``).
"""

from __future__ import annotations

from typing import Any, Callable, ClassVar

import gymnasium as gym
import numpy as np

from shaped_es.envs.core import EPISODE_SEED_HIGH, BatchCore


def single_info(info: dict[str, np.ndarray]) -> dict[str, Any]:
    """Row 0 of a core's batched ``info``: ``(B, ...)`` arrays -> ``(...)``, scalars -> Python numbers."""
    out = {}
    for key, value in info.items():
        v = value[0]
        out[key] = v.item() if np.ndim(v) == 0 else v  # (B, ...) -> (...) for B = 1
    return out


class BatchCoreEnv(gym.Env):
    """One copy of a ``BatchCore``: ``reset``/``step`` run the core on a batch of one and unwrap it.

    A new env is a core plus a config: write a ``BatchCore`` and a typed config with
    ``make_config(preset, **overrides)``, subclass this with ``env_id``, ``core_cls``, ``make_config``
    (and ``obs_bound``, ``fps``, ``render_frame`` where they differ), and add it to ``envs.BUILTIN``.

    ``reset(seed=s)`` plays the episode ``batch_core.reset([s])`` plays; without a seed the episode seed
    is drawn from ``self.np_random``. ``info`` is the core's (``position``, ``waypoint``, the
    ``reward_<term>`` terms and the env's extras) for the one copy. ``batch_core`` is the core itself,
    which the rollout layer steps directly for a whole population.
    """

    metadata: ClassVar[dict[str, Any]] = {"render_modes": ["rgb_array"], "render_fps": 10}
    env_id: ClassVar[str]
    core_cls: ClassVar[Callable[[Any], BatchCore]]  # core_cls(config) -> the batched core
    make_config: ClassVar[Callable[..., Any]]  # a staticmethod: make_config(preset, **overrides) -> config
    obs_bound: ClassVar[float] = np.inf  # the observation space is Box(-obs_bound, obs_bound)

    def __init__(self, render_mode: str | None = None, preset: str = "default", **overrides: Any):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"{self.env_id}: render_mode must be one of {self.metadata['render_modes']}")
        self.config = self.make_config(preset, **overrides)
        self.batch_core = self.core_cls(self.config)
        self.metadata = {**self.metadata, "render_fps": self.fps(self.config)}
        self.render_mode = render_mode
        self.observation_space, self.action_space = self.spaces(self.batch_core)
        self._state = None

    @classmethod
    def spaces(cls, core: BatchCore) -> tuple[gym.spaces.Box, gym.spaces.Box]:
        """(observation space, action space) of one copy, from the core's dims."""
        obs = gym.spaces.Box(-cls.obs_bound, cls.obs_bound, (core.obs_dim,), np.float32)
        return obs, gym.spaces.Box(-1.0, 1.0, (core.act_dim,), np.float32)

    @staticmethod
    def fps(config: Any) -> int:
        """Frames per second of a rendered episode (one frame a step of ``config.dt`` seconds)."""
        return int(round(1.0 / config.dt))

    @property
    def state(self):
        """The core's state of this env's single copy (``None`` before ``reset``)."""
        return self._state

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(EPISODE_SEED_HIGH))
        self._state, obs, info = self.batch_core.reset(np.array([episode_seed], dtype=np.int64))
        return obs[0], single_info(info)

    def step(self, action):
        if self._state is None:
            raise RuntimeError(f"{self.env_id}: call reset() before step()")
        act = np.asarray(action, dtype=np.float32).reshape(1, self.batch_core.act_dim)  # (1, act)
        self._state, obs, rew, term, trunc, info = self.batch_core.step(self._state, act)
        return obs[0], float(rew[0]), bool(term[0]), bool(trunc[0]), single_info(info)

    def waypoint_controller(self, obs, info: dict) -> np.ndarray:
        """The core's scripted waypoint controller (``envs/core.py`` hook) for this env's single copy:
        the action ``(act_dim,)`` it takes after ``obs`` and ``info`` (the last ones this env returned)."""
        hook = getattr(self.batch_core, "waypoint_controller", None)
        if hook is None or self._state is None:
            raise RuntimeError(f"{self.env_id}: no waypoint controller" if hook is None
                               else f"{self.env_id}: call reset() before waypoint_controller()")
        batched = {k: np.asarray(v)[None] for k, v in info.items()}  # (...) -> (1, ...)
        return hook(self._state, np.asarray(obs, np.float32)[None], batched)[0]

    def render(self):
        if self.render_mode != "rgb_array" or self._state is None:
            return None
        return self.render_frame(self._state)

    def render_frame(self, state: Any) -> np.ndarray:
        """An ``rgb_array`` frame of the single copy in ``state`` (the env's renderer)."""
        raise NotImplementedError(f"{self.env_id} does not render")
