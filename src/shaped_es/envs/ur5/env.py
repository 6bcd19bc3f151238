"""``UR5Reach-v0``: a UR5 arm following quadratic-Bezier waypoints to a target (paper, Sec. IV, "UR5
Robot arm in ROS Gazebo"), as a thin Gymnasium ``Env`` over the batched core (``core.py``) with B = 1.

=================  ======================================================================================
Action             ``Box(-1, 1, (5,))``: normalized torques of shoulder_pan, shoulder_lift, elbow,
                   wrist_1, wrist_2 (x 150, 150, 150, 28, 28 N m); wrist_3 fixed; gravity compensated
Observation        ``Box(-inf, inf, (13,))``: joint angles (5), joint velocities (5), target - end
                   effector (3). No waypoints.
Reward             ``reward_waypoint`` +M/H when the end effector ends a step within 0.1 of the next
                   waypoint (which then advances by one) + ``reward_step`` -0.1 + ``reward_collision``
                   -50 on any contact (the episode then terminates)
Episode            fixed start pose, target sampled in the upper hemisphere, M = H = 100 steps
info               ``position`` (3,) end effector, ``waypoint`` (3,) next Bezier point, ``target`` (3,),
                   ``waypoint_index``, and the three reward terms (step only)
=================  ======================================================================================

``gymnasium.make("shaped_es:UR5Reach-v0", preset="paper", reach_radius=0.05, ...)``: any field of
:class:`~shaped_es.envs.ur5.config.UR5Config` is a keyword. ``reset(seed=s)`` plays the same episode as
``env.unwrapped.batch_core.reset([s])``; without a seed the episode seed comes from ``self.np_random``.

Registered as ``make_limited`` (``UR5ReachEnv`` under a ``TimeLimit`` of the config's ``max_steps``, so
``env.spec.max_episode_steps`` is the horizon of whatever preset and overrides were asked for) and, for
``gymnasium.make_vec``, ``UR5ReachVectorEnv`` (the batched core as a ``VectorEnv``, ``envs/vector.py``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from shaped_es.envs.ur5.bezier import bezier_waypoints
from shaped_es.envs.ur5.config import make_config
from shaped_es.envs.ur5.core import ACT_DIM, OBS_DIM, UR5Core
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.vector import BatchCoreVectorEnv


class UR5ReachEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(self, render_mode: str | None = None, preset: str = "default", width: int = 480,
                 height: int = 360, **overrides: Any):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"UR5Reach-v0: render_mode must be one of {self.metadata['render_modes']}")
        self.config = make_config(preset, **overrides)
        self.batch_core = UR5Core(self.config)
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.config.control_dt))}
        self.render_mode, self._size = render_mode, (width, height)
        self.observation_space = gym.spaces.Box(-np.inf, np.inf, (OBS_DIM,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (ACT_DIM,), np.float32)
        self._state = None
        self._renderer = None

    @staticmethod
    def _single(info: dict[str, np.ndarray]) -> dict[str, Any]:
        out = {}
        for key, value in info.items():
            v = value[0]
            out[key] = v.item() if np.ndim(v) == 0 else v  # (B, ...) -> (...) for B = 1
        return out

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(2**63 - 1))
        self._state, obs, info = self.batch_core.reset(np.array([episode_seed], dtype=np.int64))
        return obs[0], self._single(info)

    def step(self, action):
        if self._state is None:
            raise RuntimeError("UR5Reach-v0: call reset() before step()")
        act = np.asarray(action, dtype=np.float32).reshape(1, ACT_DIM)
        self._state, obs, rew, term, trunc, info = self.batch_core.step(self._state, act)
        return obs[0], float(rew[0]), bool(term[0]), bool(trunc[0]), self._single(info)

    def render(self):
        if self.render_mode != "rgb_array" or self._state is None:
            return None
        if self._renderer is None:
            from shaped_es.envs.ur5.render import UR5Renderer

            self._renderer = UR5Renderer(self.batch_core.model, *self._size)
        s, cfg = self._state, self.config
        waypoints = bezier_waypoints(s.start, cfg.control_point, s.target, cfg.num_waypoints)[0]  # (H, 3)
        return self._renderer.render(s.qpos[0], s.target[0], waypoints, int(s.index[0]))

    def close(self):
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


make_limited = limited_entry_point(UR5ReachEnv)  # the registered entry point


class UR5ReachVectorEnv(BatchCoreVectorEnv):
    """``num_envs`` arms stepped by one ``UR5Core`` (``gymnasium.make_vec``'s ``vector_entry_point``)."""

    def __init__(self, num_envs: int = 1, preset: str = "default", max_episode_steps: int | None = None,
                 render_mode: str | None = None, **overrides: Any):
        config = make_config(preset, **overrides)
        self.config = config
        super().__init__(UR5Core(config), gym.spaces.Box(-np.inf, np.inf, (OBS_DIM,), np.float32),
                         gym.spaces.Box(-1.0, 1.0, (ACT_DIM,), np.float32), num_envs=num_envs,
                         max_episode_steps=max_episode_steps, render_mode=render_mode,
                         metadata={"render_modes": [], "render_fps": int(round(1.0 / config.control_dt))})
