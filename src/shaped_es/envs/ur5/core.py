"""Batched core of UR5Reach-v0: ``B`` UR5 arms stepped at once in MuJoCo (``mujoco.batch``), state in ->
state out. Task of the paper, Sec. IV "UR5 Robot arm in ROS Gazebo"; contract in ``envs/core.py``.

Dynamics. Action ``a`` ``(B, 5)`` in ``[-1, 1]`` = normalized torques of the 5 actuated joints
(``tau = a * torque_limits``; wrist 3 is fixed). Gravity compensation: every link has MuJoCo's
``gravcomp = 1``, a passive force cancelling its weight exactly, as the UR controller's gravity model
does, so the torques move the arm instead of holding it up. Joint damping ``torque_limit / pi`` makes
full torque settle near the UR5's 180 deg/s joint speed. One env step = ``frame_skip`` physics steps.

Waypoints and reward (paper, Sec. IV). H points of the quadratic Bezier curve from the start end
effector P0 through P1 to the target P2 (``bezier.py``). Waypoint rule: ``index`` is the next waypoint
not yet reached. After each step, if the end effector is within ``reach_radius`` of it, the step earns
``+M/H`` and ``index`` advances by one -- at most one waypoint per step, so the H = M points form a
timed path (CarRacing's tile reward, which the paper follows: each waypoint pays once). Every step
costs ``-0.1``; any contact (arm-ground or arm-arm, checked after every physics step) costs ``-50``
and ends the episode. The reward is the sum of ``info["reward_waypoint"]``, ``["reward_step"]`` and
``["reward_collision"]``. Returns: at most ``H * M/H - M * 0.1 = 90`` (the hand-written follower in
``controller.py`` gets it); standing still earns about -4 (the ~6 waypoints within 0.1 of the start); the
paper's -2.8 after 200 generations lies just above that.

Observation ``(B, 13)`` float32: joint angles (5), joint velocities (5), target minus end effector (3)
(with ``observe_phase``, ``(B, 14)``: and the phase ``steps / max_steps``). The policy never sees the
waypoints; ``info["position"]`` is the end effector and ``info["waypoint"]``
the next waypoint (both ``(B, 3)``, world frame), at reset and after every step.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np
from mujoco import batch as mj_batch

from shaped_es.envs.ur5.bezier import bezier_point, waypoint_t
from shaped_es.envs.ur5.config import UR5Config
from shaped_es.envs.ur5.controller import waypoint_controller

MODEL_XML = Path(__file__).with_name("ur5.xml")
JOINTS = ("shoulder_pan", "shoulder_lift", "elbow", "wrist_1", "wrist_2")
EE_SITE = "ee"
OBS_DIM, ACT_DIM, POS_DIM = 13, 5, 3
_POS = mujoco.mjtStage.mjSTAGE_POS.value


@dataclass(frozen=True)
class UR5State:
    """Explicit state of ``B`` episodes; ``step`` never mutates it."""

    qpos: np.ndarray  # (B, 5) float64, joint angles
    qvel: np.ndarray  # (B, 5) float64, joint velocities
    effector: np.ndarray  # (B, 3) float64, tool flange at qpos (derived; kept so ended rows stay pure)
    start: np.ndarray  # (B, 3) float64, P0: end effector at reset
    target: np.ndarray  # (B, 3) float64, P2: sampled target
    index: np.ndarray  # (B,) int64, next waypoint not yet reached (H once all are)
    steps: np.ndarray  # (B,) int64, steps taken
    done: np.ndarray  # (B,) bool, episode over (terminated or truncated)

    @property
    def batch_size(self) -> int:
        return int(self.qpos.shape[0])


def build_model(cfg: UR5Config) -> mujoco.MjModel:
    """Compile ``ur5.xml`` with the config's physics (timestep, torques, damping, armature, gravcomp)."""
    spec = mujoco.MjSpec.from_file(str(MODEL_XML))
    spec.option.timestep = cfg.timestep
    for i, name in enumerate(JOINTS):
        spec.joint(name).damping[0] = cfg.joint_damping[i]
        spec.joint(name).armature = cfg.armature[i]
        spec.actuator(name).gear[0] = cfg.torque_limits[i]
    for body in spec.bodies[1:]:
        body.gravcomp = cfg.gravity_compensation
    return spec.compile()


def sample_targets(rng: np.random.Generator, cfg: UR5Config) -> np.ndarray:
    """One target in the configured upper-hemisphere shell (uniform in area over the zone), ``(3,)``."""
    r = rng.uniform(*cfg.target_radius)
    sin_el = rng.uniform(np.sin(cfg.target_elevation[0]), np.sin(cfg.target_elevation[1]))
    az = rng.uniform(*cfg.target_azimuth)
    cos_el = np.sqrt(1.0 - sin_el * sin_el)
    return r * np.array([cos_el * np.cos(az), cos_el * np.sin(az), sin_el])


class UR5Core:
    """Steps ``B`` UR5Reach episodes at once (the ``BatchCore`` protocol of ``envs/core.py``).

    MuJoCo ``Batch`` objects (one per batch size) are scratch: each call loads the state's joint
    positions and velocities into them, so results depend only on ``(state, action)``.
    """

    obs_dim = OBS_DIM
    act_dim = ACT_DIM
    pos_dim = POS_DIM

    def __init__(self, config: UR5Config | None = None):
        self.config = (config or UR5Config()).validate()
        self.obs_dim = OBS_DIM + int(self.config.observe_phase)  # + the phase column
        self.max_steps = self.config.max_steps
        self.model = build_model(self.config)
        self._batches: dict[int, mj_batch.Batch] = {}
        self._p1 = np.asarray(self.config.control_point, dtype=np.float64)  # (3,)
        self._ee = self.model.site(EE_SITE).id

    # ----------------------------------------------------------------------------------- helpers
    def _batch(self, n: int) -> mj_batch.Batch:
        if n not in self._batches:
            b = mj_batch.Batch(self.model, n, nthread=self.config.threads)
            b.bind("site_xpos"), b.bind("ncon")  # outputs are filled only once bound, so bind first
            self._batches[n] = b
        return self._batches[n]

    def end_effector(self, qpos: np.ndarray) -> np.ndarray:
        """World position of the tool flange for joint angles ``(B, 5)`` -> ``(B, 3)`` (MuJoCo kinematics)."""
        b = self._batch(qpos.shape[0])
        b.bind("qpos")[:] = qpos
        b.forward(stage=_POS)
        return b.bind("site_xpos")[:, self._ee].copy()  # (B, 3)

    def waypoint(self, state: UR5State) -> np.ndarray:
        """Next waypoint ``B(index / (H - 1))`` of every episode, ``(B, 3)``."""
        t = waypoint_t(state.index, self.config.num_waypoints)  # (B,)
        return bezier_point(state.start, self._p1, state.target, t)  # (B, 3)

    def _obs(self, qpos, qvel, target, ee, steps) -> np.ndarray:
        cols = [qpos, qvel, target - ee]  # (B, 5), (B, 5), (B, 3)
        if self.config.observe_phase:
            cols.append((steps / self.config.max_steps)[:, None])  # (B, 1) the episode's phase
        return np.concatenate(cols, axis=1).astype(np.float32)  # (B, 13) or (B, 14)

    # ----------------------------------------------------------------------------------- protocol
    def reset(self, seeds: np.ndarray) -> tuple[UR5State, np.ndarray, dict[str, np.ndarray]]:
        cfg = self.config
        seeds = np.asarray(seeds, dtype=np.int64).reshape(-1)
        B = seeds.shape[0]
        q0 = np.asarray(cfg.start_qpos, dtype=np.float64)
        qpos, target = np.empty((B, 5)), np.empty((B, 3))
        for i, s in enumerate(seeds):  # one generator per episode: its seed alone decides it
            rng = np.random.default_rng(int(s))
            target[i] = sample_targets(rng, cfg)
            qpos[i] = q0 + rng.uniform(-cfg.start_qpos_noise, cfg.start_qpos_noise, 5)
        ee = self.end_effector(qpos)  # (B, 3)
        state = UR5State(qpos=qpos, qvel=np.zeros((B, 5)), effector=ee, start=ee.copy(), target=target,
                         index=np.zeros(B, dtype=np.int64), steps=np.zeros(B, dtype=np.int64),
                         done=np.zeros(B, dtype=bool))
        info = {"position": ee.copy(), "waypoint": self.waypoint(state), "target": target.copy(),
                "waypoint_index": state.index.copy()}
        return state, self._obs(state.qpos, state.qvel, target, ee, state.steps), info

    def step(self, state: UR5State, action: np.ndarray):
        cfg = self.config
        B = state.batch_size
        act = np.clip(np.asarray(action, dtype=np.float64).reshape(B, ACT_DIM), -1.0, 1.0)  # (B, 5)
        alive = ~state.done
        ids = None if alive.all() else np.flatnonzero(alive)
        b = self._batch(B)
        b.bind("qpos")[:] = state.qpos
        b.bind("qvel")[:] = state.qvel
        b.bind("ctrl")[:] = act
        ncon = np.zeros((B, cfg.frame_skip), dtype=np.int32)  # (B, frame_skip)
        if ids is None or ids.size:
            rec = b.rollout(cfg.frame_skip, record=("ncon",), ids=ids)["ncon"]  # (n, frame_skip)
            b.forward(ids=ids, stage=_POS)  # kinematics + collisions at the new state
            ncon[alive if ids is not None else slice(None)] = rec
        qpos, qvel = b.bind("qpos").copy(), b.bind("qvel").copy()  # (B, 5) each
        ee = np.where(alive[:, None], b.bind("site_xpos")[:, self._ee], state.effector)  # (B, 3)
        # record k holds the contacts of the state before physics step k: skip k = 0 (checked last call)
        collision = ((ncon[:, 1:] > 0).any(axis=1) | (b.bind("ncon") > 0)) & alive  # (B,)

        reached = alive & (state.index < cfg.num_waypoints) & (
            np.linalg.norm(ee - self.waypoint(state), axis=1) < cfg.reach_radius)  # (B,)
        r_wp = np.where(reached, cfg.waypoint_reward, 0.0)  # +M/H per waypoint (paper)
        r_step = np.where(alive, -cfg.step_penalty, 0.0)  # -0.1 every step (paper)
        r_col = np.where(collision, -cfg.collision_penalty, 0.0)  # -50 on collision (paper)
        steps = state.steps + alive
        terminated = collision & cfg.terminate_on_collision
        truncated = alive & ~terminated & (steps >= cfg.max_steps)
        new = UR5State(qpos=qpos, qvel=qvel, effector=ee, start=state.start, target=state.target,
                       index=state.index + reached, steps=steps,
                       done=state.done | terminated | truncated)
        info = {"position": ee.copy(), "waypoint": self.waypoint(new), "target": state.target.copy(),
                "waypoint_index": new.index.copy(), "collision": collision,
                "reward_waypoint": r_wp, "reward_step": r_step, "reward_collision": r_col}
        reward = r_wp + r_step + r_col
        return new, self._obs(qpos, qvel, state.target, ee, steps), reward, terminated, truncated, info

    def waypoint_controller(self, state: UR5State, obs: np.ndarray, info: dict) -> np.ndarray:
        """The env's scripted waypoint follower (``envs/core.py`` hook): resolved-rate control toward
        ``info["waypoint"]`` (``controller.py``) -> ``(B, 5)`` in ``[-1, 1]``."""
        return waypoint_controller(self.config, obs, info["position"], info["waypoint"])
