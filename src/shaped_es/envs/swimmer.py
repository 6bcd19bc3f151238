"""``SwimmerWay-v0``: Gymnasium's MuJoCo ``Swimmer-v5`` (a 3-link planar swimmer in a viscous fluid, two
joint torques) with timed waypoints along +x, cut to 100 steps: a body whose displacement comes from a
gait (undulation), not from any one action.

The episodes are Swimmer-v5's for their first 100 steps: its model file (``swimmer.xml`` of Gymnasium's
assets), its reset noise drawn in its order from ``gymnasium.utils.seeding.np_random(seed)``, its frame
skip, observation and reward (tested against ``gymnasium.make("Swimmer-v5")``), stepped by a batched
core (``mujoco.batch``, as UR5Reach-v0).

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: the two joint torques (Swimmer-v5's)
Observation        ``Box(-inf, inf, (8,))``: Swimmer-v5's: body angle and joint angles (3), velocities of
                   the slides, body and joints (5). No position, no waypoints.
Reward             Swimmer-v5's: ``reward_forward`` the x velocity (m/s) + ``reward_ctrl`` -1e-4 |a|^2
Episode            Swimmer-v5's start (+-0.1 noise on positions and velocities); 100 steps of 0.04 s (4 s)
info               ``position`` (2,) the front body's slide (x, y), ``waypoint`` (2,) its scheduled place
                   after the next step: ``start + (speed * dt * (t + 1), 0)``, ``waypoint_index``, the terms
=================  ======================================================================================

A return is 100 x the mean x velocity (m/s): 30 is 0.3 m/s.

Waypoint controller (an oracle of a kind: a gait, not an inverse of the waypoint): the waypoints run
along +x, so it is the open-loop forward undulation ``a_j = sin(2 pi f t dt + phase_j)`` (f = 0.8 Hz,
phases 0 and -60 deg: the best of a 4 x 3 grid over 150 steps), which keeps the body near them once
under way (0.21 m/s over 150 steps against their 0.2). It does not read the waypoint: gating the gait by the body's lag behind it cut its return in half
(the front body's x oscillates over each stroke, so the gate stops the gait mid-stroke).

Threshold (``reward_threshold`` 30): a mean forward speed of 0.3 m/s from rest, faster than the
waypoints. Not the controller's return less a margin: the gait scores 19.0 (20 episodes, min 17.0) and
random MLP policies already undulate (Vanilla-ES's generation-0 test reward: 23.4), so the threshold is
set where learning shows: Vanilla-ES (defaults) first reaches it at generation 13 and 9 (seeds 0, 1). Zero torque
scores 0.5 (the start's velocity noise).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from shaped_es.envs.batch_env import BatchCoreEnv
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.mujoco_batch import FrameSkipConfig, MujocoBatchCore
from shaped_es.envs.presets import preset_config
from shaped_es.envs.vector import vector_entry_point

ENV_ID = "SwimmerWay-v0"
REWARD_THRESHOLD = 30.0  # see the module docstring
OBS_DIM, ACT_DIM, POS_DIM = 8, 2, 2


@dataclass(frozen=True)
class SwimmerWayConfig(FrameSkipConfig):
    max_steps: int = 100  # the episode is truncated after this many steps (Swimmer-v5: 1000)
    waypoint_speed: float = 0.2  # the waypoints move along +x at this speed (m/s)
    frame_skip: int = 4  # Swimmer-v5's (dt = 0.04 s)
    forward_reward_weight: float = 1.0  # Swimmer-v5's
    ctrl_cost_weight: float = 1e-4  # Swimmer-v5's
    reset_noise_scale: float = 0.1  # Swimmer-v5's
    gait_frequency: float = 0.8  # the controller's undulation (Hz)
    gait_phase: float = -math.pi / 3  # the controller's second joint's phase lag (rad)
    threads: int = 1  # MuJoCo batch threads (no effect on results)

    def validate(self) -> "SwimmerWayConfig":
        if self.max_steps <= 0 or self.frame_skip <= 0 or self.threads < 0 or self.reset_noise_scale < 0:
            raise ValueError(f"{ENV_ID}: max_steps and frame_skip must be positive, reset_noise_scale >= 0")
        return self


PRESETS = {"default": SwimmerWayConfig()}


def make_config(preset: str = "default", **overrides: Any) -> SwimmerWayConfig:
    return preset_config(ENV_ID, PRESETS, preset, overrides)


@dataclass(frozen=True)
class SwimmerState:
    qpos: np.ndarray  # (B, 5) x, y slides, body angle, two joints
    qvel: np.ndarray  # (B, 5)
    start: np.ndarray  # (B, 2) slides at reset
    steps: np.ndarray  # (B,) int64
    done: np.ndarray  # (B,) bool

    @property
    def batch_size(self) -> int:
        return int(self.qpos.shape[0])


class SwimmerWayCore(MujocoBatchCore):
    """``B`` Swimmer-v5 episodes at once (``BatchCore`` protocol of ``envs/core.py``)."""

    obs_dim, act_dim, pos_dim = OBS_DIM, ACT_DIM, POS_DIM
    config_cls, asset = SwimmerWayConfig, "swimmer.xml"

    @staticmethod
    def _obs(qpos, qvel) -> np.ndarray:
        return np.concatenate([qpos[:, 2:], qvel], axis=1).astype(np.float32)  # (B, 8)

    def waypoint(self, state: SwimmerState) -> np.ndarray:
        cfg = self.config
        ahead = cfg.waypoint_speed * cfg.dt * (state.steps + 1)  # (B,)
        return state.start + np.stack([ahead, np.zeros_like(ahead)], axis=1)  # (B, 2)

    def _info(self, state: SwimmerState) -> dict[str, np.ndarray]:
        return {"position": state.qpos[:, :2].copy(), "waypoint": self.waypoint(state),
                "waypoint_index": state.steps + 1}

    def draw_reset(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Swimmer-v5's reset_model, draw for draw."""
        m, c = self.model, self.config.reset_noise_scale
        return m.qpos0 + rng.uniform(low=-c, high=c, size=m.nq), rng.uniform(low=-c, high=c, size=m.nv)

    def reset(self, seeds: np.ndarray):
        qpos, qvel = self.reset_joints(seeds)
        B = qpos.shape[0]
        state = SwimmerState(qpos=qpos, qvel=qvel, start=qpos[:, :2].copy(), steps=np.zeros(B, dtype=np.int64),
                             done=np.zeros(B, dtype=bool))
        return state, self._obs(qpos, qvel), self._info(state)

    def step(self, state: SwimmerState, action: np.ndarray):
        cfg = self.config
        B = state.batch_size
        act = self.clip_action(action, B)  # (B, 2)
        alive, qpos, qvel, _ = self.advance(state, act)  # (B, 5) each
        x_vel = (qpos[:, 0] - state.qpos[:, 0]) / cfg.dt  # (B,)
        r_fwd = np.where(alive, cfg.forward_reward_weight * x_vel, 0.0)
        r_ctrl = np.where(alive, -cfg.ctrl_cost_weight * np.square(act).sum(axis=1), 0.0)
        steps = state.steps + alive
        truncated = alive & (steps >= cfg.max_steps)
        new = SwimmerState(qpos=qpos, qvel=qvel, start=state.start, steps=steps, done=state.done | truncated)
        info = {**self._info(new), "reward_forward": r_fwd, "reward_ctrl": r_ctrl}
        return new, self._obs(qpos, qvel), r_fwd + r_ctrl, np.zeros(B, dtype=bool), truncated, info

    def waypoint_controller(self, state: SwimmerState, obs: np.ndarray, info: dict) -> np.ndarray:
        """The forward undulation at the episode's step (module docstring), ``(B, 2)``."""
        cfg = self.config
        w = 2 * math.pi * cfg.gait_frequency * cfg.dt * state.steps  # (B,) the gait's phase
        return np.stack([np.sin(w), np.sin(w + cfg.gait_phase)], axis=1).astype(np.float32)  # (B, 2)


class SwimmerWayEnv(BatchCoreEnv):
    metadata = {"render_modes": [], "render_fps": 25}
    env_id = ENV_ID
    core_cls = SwimmerWayCore
    make_config = staticmethod(make_config)


make_limited = limited_entry_point(SwimmerWayEnv)  # the registered entry point
SwimmerWayVectorEnv = vector_entry_point(SwimmerWayEnv)  # the registered vector_entry_point
