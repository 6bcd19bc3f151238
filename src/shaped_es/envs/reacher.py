"""``ReacherWay-v0``: Gymnasium's MuJoCo ``Reacher-v5`` (a torque-driven 2-link planar arm) with timed
waypoints from the start fingertip to the target, the suite's second arm beside UR5Reach-v0.

The episodes are Reacher-v5's, episode for episode: its model file (``reacher.xml`` of Gymnasium's
assets), its reset distribution drawn in its order from ``gymnasium.utils.seeding.np_random(seed)``, its
frame skip, observation and reward, so ``reset(seed=s)`` and the same actions give Reacher-v5's
observations and rewards (to float32 rounding of the observation; tested). They are stepped by a batched
core (``mujoco.batch``, as UR5Reach-v0), so a population's episodes run in one call instead of one
Python env each (~15x faster a generation). The contract and the controller are what this env adds:

=================  ======================================================================================
Action             ``Box(-1, 1, (2,))``: joint torques (x 200, Reacher-v5's gear)
Observation        ``Box(-inf, inf, (10,))``: Reacher-v5's: cos and sin of the two joints (4), the target
                   (2), joint velocities (2), fingertip - target (2). No waypoints.
Reward             Reacher-v5's: ``reward_dist`` -|fingertip - target| + ``reward_ctrl`` -|a|^2
Episode            Reacher-v5's random start (arm near straight along +x) and target (within 0.2 of the
                   base); 50 steps (1 s)
info               ``position`` (2,) fingertip (x, y), ``waypoint`` (2,) where the schedule puts it after
                   the next step, ``target`` (2,), ``waypoint_index``, and the two reward terms
=================  ======================================================================================

Timed waypoints: after ``t`` steps the next waypoint is ``start + (target - start) * min(1, (t + 1) /
reach_steps)`` (``start``: the fingertip at reset): the straight line walked in ``reach_steps`` = 15
steps, then the target.

Waypoint controller: resolved-rate control. Desired fingertip velocity ``gain * (waypoint -
fingertip)``, joint velocities by damped least squares with the 2-link Jacobian (links 0.1 and 0.11),
torques ``kv * (qd_des - qd)`` clipped to ``[-1, 1]``.

Threshold (``reward_threshold`` -6.5): the controller scores -5.9 (mean of 20 episodes; Reacher-v5's own
threshold -3.75 needs a faster reach than a 15-step schedule); zero torque scores -11.5, so -6.5 is a
reach that gets most of the way to the target early. Calibration (default settings): Vanilla-ES (seeds
0, 1) and CMA-ES (seed 0) do not reach it in 100 generations (their test rewards stay at -7.5 to -11);
``shaped`` with the controller's labels (``shaping.labels=controller``, seed 0) reaches it at generation 8.

Labels: no inverse of this arm's dynamics drives it past the threshold (a one-step fingertip step is
almost all velocity); the default's servo rival (``shaping.inverse_dynamics.rival_servo``,
``shaping/forward_servo.py``: a learned forward model's damped transpose servo) does, and its candidate
solves 16 of seeds 0-19 in about half the budget, where Vanilla-ES solves none and CMA-ES one
(``docs/shaped-results.md``, "A servo rival").
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from shaped_es.envs.batch_env import BatchCoreEnv
from shaped_es.envs.core import limited_entry_point
from shaped_es.envs.mujoco_batch import FrameSkipConfig, MujocoBatchCore
from shaped_es.envs.presets import preset_config
from shaped_es.envs.vector import vector_entry_point

ENV_ID = "ReacherWay-v0"
REWARD_THRESHOLD = -6.5  # see the module docstring
LINKS = (0.1, 0.11)  # Reacher-v5's link lengths: joint0 -> joint1, joint1 -> fingertip
OBS_DIM, ACT_DIM, POS_DIM = 10, 2, 2


@dataclass(frozen=True)
class ReacherWayConfig(FrameSkipConfig):
    max_steps: int = 50  # Reacher-v5's time limit
    reach_steps: int = 15  # the schedule reaches the target after this many steps
    frame_skip: int = 2  # Reacher-v5's physics steps per env step (dt = 0.02 s)
    reward_dist_weight: float = 1.0  # Reacher-v5's
    reward_control_weight: float = 1.0  # Reacher-v5's
    threads: int = 1  # MuJoCo batch threads (no effect on results)

    def validate(self) -> "ReacherWayConfig":
        if self.max_steps <= 0 or self.reach_steps <= 0 or self.frame_skip <= 0 or self.threads < 0:
            raise ValueError(f"{ENV_ID}: max_steps, reach_steps and frame_skip must be positive")
        return self


PRESETS = {"default": ReacherWayConfig()}


def make_config(preset: str = "default", **overrides: Any) -> ReacherWayConfig:
    return preset_config(ENV_ID, PRESETS, preset, overrides)


def timed_waypoint(start: np.ndarray, target: np.ndarray, k: np.ndarray, reach_steps: int) -> np.ndarray:
    """Waypoint ``k`` of the schedule, ``start + (target - start) * min(1, k / reach_steps)``; ``(B, 2)``
    arrays and ``k`` ``(B,)`` (or one episode's ``(2,)`` and a number)."""
    frac = np.minimum(1.0, np.asarray(k, dtype=np.float64) / reach_steps)
    return start + (target - start) * (frac[..., None] if np.ndim(frac) else frac)


def jacobian(q: np.ndarray) -> np.ndarray:
    """d fingertip / d q of joint angles ``(B, 2)``, ``(B, 2, 2)`` (planar forward kinematics)."""
    l1, l2 = LINKS
    s0, c0 = np.sin(q[:, 0]), np.cos(q[:, 0])
    s01, c01 = np.sin(q[:, 0] + q[:, 1]), np.cos(q[:, 0] + q[:, 1])
    return np.stack([np.stack([-l1 * s0 - l2 * s01, -l2 * s01], -1),
                     np.stack([l1 * c0 + l2 * c01, l2 * c01], -1)], axis=1)


def resolved_rate(obs: np.ndarray, position: np.ndarray, waypoint: np.ndarray, gain: float = 20.0,
                  damping_lambda: float = 0.15, kv: float = 0.1) -> np.ndarray:
    """Torque actions ``(B, 2)`` in ``[-1, 1]`` moving each fingertip toward its waypoint (module
    docstring), from observations ``(B, 10)`` and contract positions ``(B, 2)``."""
    obs = np.asarray(obs, dtype=np.float64)
    q = np.arctan2(obs[:, 2:4], obs[:, 0:2])  # (B, 2) joint angles from (cos, sin)
    qd = obs[:, 6:8]  # (B, 2) joint velocities
    v = gain * (np.asarray(waypoint, np.float64) - np.asarray(position, np.float64))  # (B, 2)
    J = jacobian(q)  # (B, 2, 2)
    JJt = J @ np.swapaxes(J, 1, 2) + damping_lambda**2 * np.eye(2)  # (B, 2, 2)
    qd_des = (np.swapaxes(J, 1, 2) @ np.linalg.solve(JJt, v[..., None]))[..., 0]  # (B, 2)
    return np.clip(kv * (qd_des - qd), -1.0, 1.0).astype(np.float32)


@dataclass(frozen=True)
class ReacherState:
    qpos: np.ndarray  # (B, 4) joints (2) and target slides (2)
    qvel: np.ndarray  # (B, 4)
    tip: np.ndarray  # (B, 3) fingertip centre of mass as Reacher-v5 reads it (get_body_com)
    target: np.ndarray  # (B, 3)
    start: np.ndarray  # (B, 2) fingertip at reset
    steps: np.ndarray  # (B,) int64
    done: np.ndarray  # (B,) bool

    @property
    def batch_size(self) -> int:
        return int(self.qpos.shape[0])


class ReacherWayCore(MujocoBatchCore):
    """``B`` Reacher-v5 episodes at once (``BatchCore`` protocol of ``envs/core.py``)."""

    obs_dim, act_dim, pos_dim = OBS_DIM, ACT_DIM, POS_DIM
    config_cls, asset, bind_outputs = ReacherWayConfig, "reacher.xml", ("xipos",)

    def __init__(self, config: ReacherWayConfig | None = None):
        super().__init__(config)
        self._tip, self._target = self.model.body("fingertip").id, self.model.body("target").id

    def _obs(self, qpos, qvel, tip, target) -> np.ndarray:
        return np.concatenate([np.cos(qpos[:, :2]), np.sin(qpos[:, :2]), qpos[:, 2:], qvel[:, :2],
                               (tip - target)[:, :2]], axis=1).astype(np.float32)  # (B, 10)

    def _info(self, state: ReacherState) -> dict[str, np.ndarray]:
        k = np.minimum(state.steps + 1, self.config.reach_steps)  # (B,)
        return {"position": state.tip[:, :2].copy(), "target": state.target[:, :2].copy(), "waypoint_index": k,
                "waypoint": timed_waypoint(state.start, state.target[:, :2], k, self.config.reach_steps)}

    def draw_reset(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Reacher-v5's reset_model, draw for draw."""
        m = self.model
        qpos = rng.uniform(low=-0.1, high=0.1, size=m.nq) + m.qpos0
        while True:
            goal = rng.uniform(low=-0.2, high=0.2, size=2)
            if np.linalg.norm(goal) < 0.2:
                break
        qpos[-2:] = goal
        qvel = rng.uniform(low=-0.005, high=0.005, size=m.nv)
        qvel[-2:] = 0
        return qpos, qvel

    def reset(self, seeds: np.ndarray):
        qpos, qvel = self.reset_joints(seeds)
        B = qpos.shape[0]
        b = self._batch(B)
        b.bind("qpos")[:], b.bind("qvel")[:] = qpos, qvel
        b.forward()
        xipos = b.bind("xipos")  # (B, nbody, 3)
        tip, target = xipos[:, self._tip].copy(), xipos[:, self._target].copy()
        state = ReacherState(qpos=qpos, qvel=qvel, tip=tip, target=target, start=tip[:, :2].copy(),
                             steps=np.zeros(B, dtype=np.int64), done=np.zeros(B, dtype=bool))
        return state, self._obs(qpos, qvel, tip, target), self._info(state)

    def step(self, state: ReacherState, action: np.ndarray):
        cfg = self.config
        B = state.batch_size
        act = self.clip_action(action, B)  # (B, 2)
        # Reacher-v5 reads the bodies after mj_step, i.e. the kinematics of the last substep's start
        alive, qpos, qvel, xipos = self.advance(state, act, record="xipos")  # xipos: (B, nbody, 3)
        tip = np.where(alive[:, None], xipos[:, self._tip], state.tip)  # (B, 3)
        target = np.where(alive[:, None], xipos[:, self._target], state.target)
        r_dist = np.where(alive, -np.linalg.norm(tip - target, axis=1) * cfg.reward_dist_weight, 0.0)
        r_ctrl = np.where(alive, -np.square(act).sum(axis=1) * cfg.reward_control_weight, 0.0)
        steps = state.steps + alive
        truncated = alive & (steps >= cfg.max_steps)
        new = ReacherState(qpos=qpos, qvel=qvel, tip=tip, target=target, start=state.start, steps=steps,
                           done=state.done | truncated)
        info = {**self._info(new), "reward_dist": r_dist, "reward_ctrl": r_ctrl}
        return (new, self._obs(qpos, qvel, tip, target), r_dist + r_ctrl, np.zeros(B, dtype=bool), truncated,
                info)

    def waypoint_controller(self, state: ReacherState, obs: np.ndarray, info: dict) -> np.ndarray:
        """Resolved-rate control toward ``info["waypoint"]`` (``envs/core.py`` hook), ``(B, 2)``."""
        return resolved_rate(obs, info["position"], info["waypoint"])


class ReacherWayEnv(BatchCoreEnv):
    metadata = {"render_modes": [], "render_fps": 50}
    env_id = ENV_ID
    core_cls = ReacherWayCore
    make_config = staticmethod(make_config)


make_limited = limited_entry_point(ReacherWayEnv)  # the registered entry point
ReacherWayVectorEnv = vector_entry_point(ReacherWayEnv)  # the registered vector_entry_point
