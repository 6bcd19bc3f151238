"""A Gymnasium ``VectorEnv`` over a batched core, so ``gymnasium.make_vec`` gets the cores' speed.

``gymnasium.make_vec("shaped_es:CarNav-v0", num_envs=8, vectorization_mode="vector_entry_point")``
(the registered ``vector_entry_point``, also picked when ``vectorization_mode`` is left out) steps all
``num_envs`` copies in one call of the env's batched core instead of ``num_envs`` Python envs.

Semantics follow Gymnasium 1.x's ``SyncVectorEnv`` over ``gymnasium.make`` envs, episode for episode:

- ``reset(seed=s)`` gives sub-env ``i`` the episode ``gymnasium.make(id).reset(seed=s + i)`` plays (a list
  of seeds: one each; no seed: drawn from each sub-env's generator); ``options={"reset_mask": m}`` resets
  only the sub-envs where ``m`` is True.
- Autoreset is ``AutoresetMode.NEXT_STEP``: the step that ends an episode returns its last observation;
  the next ``step`` resets that sub-env (its action is ignored) and returns the new episode's first
  observation with reward 0 and ``terminated = truncated = False``. New episodes draw their seed from
  the sub-env's own generator, as a single env's ``reset()`` without a seed does.
- ``info`` is a dict of ``(num_envs, ...)`` arrays, each key ``k`` with its boolean mask ``"_k"``.
- Episodes are truncated after the core's ``max_steps`` (or ``make_vec(..., max_episode_steps=N)`` if
  smaller) with ``TimeLimit``'s rule, as the registered single env (truncated even if also terminated).
"""

from __future__ import annotations

import dataclasses
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.utils import seeding
from gymnasium.vector import AutoresetMode, VectorEnv
from gymnasium.vector.utils import batch_space

from shaped_es.envs.core import EPISODE_SEED_HIGH


def merge_rows(state: Any, rows: np.ndarray, sub: Any) -> Any:
    """``state`` with rows ``rows`` replaced by the rows of ``sub`` (a state of ``len(rows)`` copies).

    Works for any dataclass state whose fields are arrays with the batch as their first axis (both
    built-in cores); a core may offer its own ``merge_rows(state, rows, sub)`` instead.
    """
    out = {}
    for f in dataclasses.fields(state):
        full = np.array(getattr(state, f.name), copy=True)
        full[rows] = getattr(sub, f.name)
        out[f.name] = full
    return dataclasses.replace(state, **out)


class BatchCoreVectorEnv(VectorEnv):
    """``num_envs`` copies of a batched core (``envs/core.py`` protocol) as a Gymnasium ``VectorEnv``."""

    def __init__(self, core, single_observation_space: gym.spaces.Box, single_action_space: gym.spaces.Box,
                 num_envs: int = 1, max_episode_steps: int | None = None, render_mode: str | None = None,
                 metadata: dict | None = None):
        if int(num_envs) < 1:
            raise ValueError(f"num_envs must be positive, got {num_envs}")
        if render_mode is not None:
            raise ValueError("the batched vector env does not render; use gymnasium.make for rendering")
        if max_episode_steps is not None and int(max_episode_steps) < 1:
            max_episode_steps = None  # make(..., max_episode_steps=-1) style: no extra limit
        self.core = core
        self.num_envs = int(num_envs)
        self.single_observation_space = single_observation_space
        self.single_action_space = single_action_space
        self.observation_space = batch_space(single_observation_space, self.num_envs)
        self.action_space = batch_space(single_action_space, self.num_envs)
        self.metadata = {**(metadata or {}), "autoreset_mode": AutoresetMode.NEXT_STEP}
        self.render_mode = None
        self.max_episode_steps = None if max_episode_steps is None else int(max_episode_steps)
        self._limit = min(int(core.max_steps), self.max_episode_steps or int(core.max_steps))
        self._act_dim = int(np.prod(single_action_space.shape))
        self._rngs = [seeding.np_random(None)[0] for _ in range(self.num_envs)]
        self._state = None
        self._state_obs: np.ndarray | None = None  # (B, obs) last observations (for partial resets)
        self._last_info: dict[str, np.ndarray] = {}
        self._steps = np.zeros(self.num_envs, dtype=np.int64)  # steps of each sub-env's episode
        self._autoreset = np.zeros(self.num_envs, dtype=bool)

    # -- helpers ------------------------------------------------------------------------------------
    def _episode_seeds(self, rows: np.ndarray, seed) -> np.ndarray:
        """Episode seeds of sub-envs ``rows``, reseeding their generators like ``Env.reset(seed=...)``."""
        if seed is None:
            seeds = [None] * self.num_envs
        elif isinstance(seed, (int, np.integer)):
            seeds = [int(seed) + i for i in range(self.num_envs)]
        else:
            seeds = list(seed)
            if len(seeds) != self.num_envs:
                raise ValueError(f"reset: got {len(seeds)} seeds for {self.num_envs} envs")
        out = np.empty(len(rows), dtype=np.int64)
        for j, i in enumerate(rows):
            s = seeds[i]
            if s is not None:
                self._rngs[i] = seeding.np_random(int(s))[0]
                out[j] = int(s)
            else:
                out[j] = int(self._rngs[i].integers(EPISODE_SEED_HIGH))
        return out

    def _merge_state(self, rows: np.ndarray, sub) -> Any:
        merge = getattr(self.core, "merge_rows", None)
        return merge(self._state, rows, sub) if merge is not None else merge_rows(self._state, rows, sub)

    def _info(self, base: dict | None, rows: np.ndarray, sub: dict) -> dict[str, np.ndarray]:
        """Vector info: ``base`` (all sub-envs) with ``rows`` taken from ``sub``; a key missing for some
        sub-envs is zero there and its ``"_key"`` mask False."""
        B = self.num_envs
        out: dict[str, np.ndarray] = {}
        keys = list(base or {}) + [k for k in sub if k not in (base or {})]
        for k in keys:
            ref = np.asarray(base[k] if base is not None and k in base else sub[k])
            arr = np.zeros((B, *ref.shape[1:]), dtype=ref.dtype)
            mask = np.zeros(B, dtype=bool)
            if base is not None and k in base:
                arr[:] = base[k]
                mask[:] = True
            if k in sub:
                arr[rows] = sub[k]
                mask[rows] = True
            elif len(rows):
                arr[rows] = 0
                mask[rows] = False
            out[k], out[f"_{k}"] = arr, mask
        return out

    # -- VectorEnv API -----------------------------------------------------------------------------
    def reset(self, *, seed: int | list[int | None] | None = None, options: dict | None = None):
        super().reset(seed=seed if isinstance(seed, (int, np.integer)) else None)
        mask = None if options is None else options.get("reset_mask")
        if mask is not None:
            mask = np.asarray(mask, dtype=bool).reshape(self.num_envs)
            if self._state is None and not mask.all():
                raise ValueError("reset: the first reset must reset every sub-env (reset_mask all True)")
        rows = np.arange(self.num_envs) if mask is None else np.flatnonzero(mask)
        sub_state, sub_obs, sub_info = self.core.reset(self._episode_seeds(rows, seed))
        if self._state is None or len(rows) == self.num_envs:
            self._state, obs, info = sub_state, np.array(sub_obs, dtype=np.float32), self._info(None, rows, sub_info)
        else:
            self._state = self._merge_state(rows, sub_state)
            obs = np.array(self._state_obs, dtype=np.float32)
            obs[rows] = sub_obs
            info = self._info(self._last_info, rows, sub_info)
        self._steps[rows] = 0
        self._autoreset[rows] = False
        self._state_obs, self._last_info = obs, {k: v for k, v in info.items() if not k.startswith("_")}
        return obs.copy(), info

    def step(self, actions):
        if self._state is None:
            raise RuntimeError("call reset() before step()")
        act = np.asarray(actions, dtype=np.float32).reshape(self.num_envs, self._act_dim)  # (B, act)
        state, obs, reward, term, trunc, info = self.core.step(self._state, act)
        self._state = state
        obs = np.array(obs, dtype=np.float32)
        reward = np.array(reward, dtype=np.float64)
        term, trunc = np.array(term, dtype=bool), np.array(trunc, dtype=bool)
        self._steps += 1
        trunc |= self._steps >= self._limit  # gymnasium's TimeLimit rule, as the registered single env
        rows = np.flatnonzero(self._autoreset)
        sub_info: dict = {}
        if len(rows):  # NEXT_STEP autoreset: these sub-envs ended last step; start their next episode
            sub_state, sub_obs, sub_info = self.core.reset(self._episode_seeds(rows, None))
            self._state = self._merge_state(rows, sub_state)
            obs[rows], reward[rows], term[rows], trunc[rows] = sub_obs, 0.0, False, False
            self._steps[rows] = 0
        vinfo = self._info(info, rows, sub_info)
        self._autoreset = term | trunc
        self._state_obs, self._last_info = obs, {k: v for k, v in vinfo.items() if not k.startswith("_")}
        return obs.copy(), reward, term, trunc, vinfo

    def close_extras(self, **kwargs):
        self._state = None


def vector_entry_point(env_cls):
    """``gymnasium.make_vec``'s ``vector_entry_point`` for a ``BatchCoreEnv`` subclass: ``num_envs`` copies
    of its core, with the spaces, config keywords and frame rate of ``env_cls`` (``envs/batch_env.py``)."""

    def make_vec(num_envs: int = 1, preset: str = "default", max_episode_steps: int | None = None,
                 render_mode: str | None = None, **overrides: Any) -> BatchCoreVectorEnv:
        config = env_cls.make_config(preset, **overrides)
        core = env_cls.core_cls(config)
        env = BatchCoreVectorEnv(core, *env_cls.spaces(core), num_envs=num_envs,
                                 max_episode_steps=max_episode_steps, render_mode=render_mode,
                                 metadata={"render_modes": [], "render_fps": env_cls.fps(config)})
        env.config = config
        return env

    make_vec.__doc__ = f"``num_envs`` copies of ``{env_cls.__name__}``'s batched core as one ``VectorEnv``."
    return make_vec
