"""``CarNav-v0``: waypoint navigation in a procedurally generated town (the paper's CARLA Town07 task,
Sec. IV), as a thin Gymnasium ``Env`` over the batched core (``core.py``) with B = 1.

A car starts at a random point of the road network and must drive to a random destination along the
route of a global planner (A* on the road graph; waypoints every 1.5 m, right lane, rounded turns).

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: steer (+1 = full left, 35 deg), throttle (+1 = 3 m/s^2; negative
                   brakes, -1 = 8 m/s^2); above 25 km/h the brake is applied automatically
Observation        ``Box(-1, 1, (38,))``, table below. No waypoint coordinates.
Reward             ``reward_waypoint`` +M/H for each global waypoint passed within 0.5 m (M = max frames,
                   H = the route's number of waypoints) + ``reward_step`` -0.1 + ``reward_collision`` -50
                   on a collision (the episode then terminates)
Episode            terminates on a collision or once the last waypoint is reached or skipped; truncated
                   after M steps (``default``: M = 250, 60-120 waypoints; ``paper``: M = 1000, 800-1200)
info               ``position`` (2,) car centre, ``waypoint`` (2,) next local waypoint (both in metres,
                   town frame), the three reward terms, ``waypoint_index``, ``waypoints_reached``,
                   ``num_waypoints``, ``collision``, ``is_success``
=================  ======================================================================================

Observation layout (paper: "heading angle, odometry, linear and angular velocity, 32-beam lidar"):

=========  =============================================================================================
index      meaning (all clipped to [-1, 1])
=========  =============================================================================================
0          sin of the heading error: angle from the car's heading to the next global waypoint
1          cos of the heading error
2          odometry: metres driven / (speed limit * dt * M), in [0, 1]
3          linear velocity, forward (body frame) / speed limit
4          linear velocity, lateral (body frame, + left) / speed limit
5          angular velocity (yaw rate, + counter-clockwise) / (yaw rate at full lock and the speed limit)
6 .. 37    lidar: range / 20 m of beam j at ``yaw + 2 pi j / 32`` (j = 0 straight ahead, counter-clockwise)
=========  =============================================================================================

Local waypoint rule (``info["waypoint"]``, used only by the inverse-dynamics model): the point of the
route ``local_lookahead`` (3 m) ahead of the car's projection on it, but never beyond the next global
waypoint -- with 1.5 m spacing, the next global waypoint not yet reached; with sparse waypoints
(``waypoint_spacing=15.0``) a point between the car and it. A waypoint the car passes farther than
0.5 m away (crossing its perpendicular gate within ``skip_width``) is skipped without reward.

``gymnasium.make("shaped_es:CarNav-v0", preset="paper", waypoint_spacing=15.0, ...)``: any field of
:class:`~shaped_es.envs.carnav.config.CarNavConfig` is a keyword. ``reset(seed=s)`` plays the same
episode as ``env.unwrapped.batch_core.reset([s])``; without a seed the episode seed comes from
``self.np_random``.

Registered as ``make_limited`` (``CarNavEnv`` under a ``TimeLimit`` of the config's ``max_steps``, so
``env.spec.max_episode_steps`` is the horizon of whatever preset and overrides were asked for) and, for
``gymnasium.make_vec``, ``CarNavVectorEnv`` (the batched core as a ``VectorEnv``, ``envs/vector.py``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np

from shaped_es.envs.carnav.config import make_config
from shaped_es.envs.carnav.core import ACT_DIM, CarNavCore
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.vector import BatchCoreVectorEnv


class CarNavEnv(gym.Env):
    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, render_mode: str | None = None, preset: str = "default", **overrides: Any):
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"CarNav-v0: render_mode must be one of {self.metadata['render_modes']}")
        self.config = make_config(preset, **overrides)
        self.batch_core = CarNavCore(self.config)
        self.metadata = {**self.metadata, "render_fps": int(round(1.0 / self.config.dt))}
        self.render_mode = render_mode
        self.observation_space = gym.spaces.Box(-1.0, 1.0, (self.config.obs_dim,), np.float32)
        self.action_space = gym.spaces.Box(-1.0, 1.0, (ACT_DIM,), np.float32)
        self._state = None

    @staticmethod
    def _single(info: dict[str, np.ndarray]) -> dict[str, Any]:
        out = {}
        for key, value in info.items():
            v = value[0]
            out[key] = v.item() if np.ndim(v) == 0 else v  # (B, ...) -> (...) for B = 1
        return out

    @property
    def state(self):
        """The core's state of this env's single car (``None`` before ``reset``)."""
        return self._state

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        episode_seed = seed if seed is not None else int(self.np_random.integers(2**63 - 1))
        self._state, obs, info = self.batch_core.reset(np.array([episode_seed], dtype=np.int64))
        return obs[0], self._single(info)

    def step(self, action):
        if self._state is None:
            raise RuntimeError("CarNav-v0: call reset() before step()")
        act = np.asarray(action, dtype=np.float32).reshape(1, ACT_DIM)
        self._state, obs, rew, term, trunc, info = self.batch_core.step(self._state, act)
        return obs[0], float(rew[0]), bool(term[0]), bool(trunc[0]), self._single(info)

    def render(self):
        if self.render_mode != "rgb_array" or self._state is None:
            return None
        from shaped_es.envs.carnav.render import render_top_down

        return render_top_down(self.batch_core, self._state, 0)


make_limited = limited_entry_point(CarNavEnv)  # the registered entry point


class CarNavVectorEnv(BatchCoreVectorEnv):
    """``num_envs`` cars stepped by one ``CarNavCore`` (``gymnasium.make_vec``'s ``vector_entry_point``)."""

    def __init__(self, num_envs: int = 1, preset: str = "default", max_episode_steps: int | None = None,
                 render_mode: str | None = None, **overrides: Any):
        config = make_config(preset, **overrides)
        self.config = config
        super().__init__(CarNavCore(config), gym.spaces.Box(-1.0, 1.0, (config.obs_dim,), np.float32),
                         gym.spaces.Box(-1.0, 1.0, (ACT_DIM,), np.float32), num_envs=num_envs,
                         max_episode_steps=max_episode_steps, render_mode=render_mode,
                         metadata={"render_modes": [], "render_fps": int(round(1.0 / config.dt))})
