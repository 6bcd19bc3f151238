"""Shooting labels: the held action whose predicted path passes nearest the waypoint (a rival label variant).

Why. Where the action reaches the position only through two or three integrations -- a car steered by the
rate of its wheel, a body with inertia in every joint -- a one-step displacement hardly depends on this
step's action, so no inverse of one step (``M_phi``) and no one-step servo (``forward_servo.py``) gives a
label that drives the body: on Kart-v0 (a car driven by acceleration and steering rate) every M_phi variant's
labels drive it no better than zero action (``docs/benchmarks/suite_bodies_v7``). Over a few steps the
action shows: a wheel held for 4 steps turns the car. The labels here ask a model of those few steps
which action, held, brings the body nearest the waypoint -- random-shooting model-predictive control with
one candidate plan per action, the first step of the best plan as the label:

- a forward model ``f(s_t, a) -> (p_{t+j} - p_t)_{j=1..h}``, the displacements over the next ``h`` steps
  with the action ``a`` held, fitted on the recorded steps with ``a`` the mean action of the ``h`` steps
  (the data's actions vary; their mean is what moved the body); M_phi's lean MLP, kernels and data parts
  with inputs and targets swapped, as the servo's;
- the candidate actions :func:`candidate_actions`: a grid of 5 values per action dimension up to 2, else
  the zero action, half and full along every axis and random corners (``MAX_CANDIDATES`` in all);
- the label: ``argmin_a min_j |f_j(s_t, a) - (w_t - p_t)|``: the candidate whose path passes nearest the
  waypoint within ``h`` steps (its end alone overshoots a waypoint within reach: on Kart-v0, with the
  simulator as its model, 5.8 return against 4.7 at h = 4);
- the aim (``shoot_ahead`` k, default 1): not the waypoint itself but ``w_t + k (w_t - w_before)``, one step of
  the waypoint path past it (``w_before``: the waypoint ``w_t`` took over from, ``mphi_inputs.waypoint_before``),
  as pure pursuit looks past its waypoint. A car aiming at a waypoint inside its turning circle circles it:
  with the simulator as the model, Kart-v0 scores 9.5 aiming one step past against 6.0 at the waypoint (its
  controller 9.0); the points, the unicycle and the rover within 0.1 either way
  (``docs/benchmarks/shoot_ahead_v10``). On a timed path the step is one step of the schedule.

- a goal to hold (``hold``, ``shoot_hold``, off by default): where the row's waypoint is a goal the body reached and that stayed
  (``mphi_inputs.waypoint_held``: known in hindsight), the aim is the goal itself, not past it, and the paths are
  scored by their mean distance to it whatever ``cost``: a path through a goal is a swing past it. With the
  simulator as its model, held actions over 16 steps drive a new user's crane to 111.6 so (its controller 119.2),
  21.9 aimed past the goal by their nearest pass; learned, 10 seeds: the crane's late reward 82.1 against 60.8,
  but a quadrotor's threshold 8/10 against 10/10 (``docs/benchmarks/held_goal_v35``).

- the frame (``frame``): the world's, or the waypoint's (x toward ``w_t``, y to its left; ``frames.py``), in
  which the model predicts the paths and the aim is read. A body that observes itself only relative to itself (a
  car's heading error and lidar, a trailer's goal in its own frame) has no world heading in its state, so its
  world-frame paths cannot be predicted: held-out error (fraction of the paths' variance unexplained, random
  policies' steps) 2.3 on CarNav-v0 and 1.45 on a new user's car-and-trailer in the world frame against 0.53 and
  0.12 in the waypoint frame; every other suite and held-out body observes its world heading or velocity and
  predicts better in the world frame (0.01-0.6 against 0.16-1.0). The label probe picks the frame by this error
  (``guides/probe_shoot_frame.py``); the waypoint frame needs two planar coordinates.

With the simulator as its model and aiming at the waypoint, these labels drive Kart-v0 to 5.8 (its
controller 9.0, zero action -1.2), and as the env's controller (``shaping.labels=controller`` on such a
Kart) they solve it 10/10 in 18.8 generations where Vanilla-ES solves 6/10 in 80. Hand-written: no library
offers model-predictive labels through a learned waypoint-space model.
"""

from __future__ import annotations

from dataclasses import replace
from itertools import product

import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping.forward_servo import ForwardLabels, ForwardServo
from shaped_es.shaping.lean_mlp import FlatAdam, LeanMLP
from shaped_es.shaping.inverse_dynamics import RunningNorm
from shaped_es.shaping.mphi_inputs import episode_end, waypoint_before, waypoint_held
from shaped_es.shaping.forward_rollout import ForwardRollout
from shaped_es.shaping.frames import rotate, waypoint_angle
from shaped_es.shaping.settings import SHOOT_COSTS, SHOOT_FRAMES, SHOOT_MODELS

HORIZON = 4  # steps a candidate action is held
GRID = 5  # candidate values per action dimension (-1, -0.5, 0, 0.5, 1) while GRID ** act <= MAX_CANDIDATES
MAX_CANDIDATES = 64
CANDIDATE_SEED = 1_000_023  # the random corners' stream (fixed: the same candidates in every run)


def candidate_actions(act_dim: int) -> np.ndarray:
    """The held actions a label chooses from, ``(K, act)`` in ``[-1, 1]``."""
    values = np.linspace(-1.0, 1.0, GRID)
    if GRID ** act_dim <= MAX_CANDIDATES:
        return np.array(list(product(values, repeat=act_dim)), np.float32)  # (GRID^act, act)
    eye = np.eye(act_dim)
    rows = [np.zeros(act_dim)] + [s * v * eye[i] for i in range(act_dim) for s in (-1, 1) for v in (0.5, 1.0)]
    rest = max(0, MAX_CANDIDATES - len(rows))
    corners = np.random.default_rng(CANDIDATE_SEED).choice([-1.0, 1.0], size=(rest, act_dim))  # (rest, act)
    return np.concatenate([np.array(rows), corners]).astype(np.float32)[:MAX_CANDIDATES]


class ForwardChunk(ForwardServo):
    """``f(s_t, a) -> (p_{t+j} - p_t)_{j=1..h}`` (flattened ``h x d`` outputs, scaled by ``step_scale``):
    the servo's model (data set, training, checkpoint, data parts) over ``h`` steps."""

    def __init__(self, obs_dim: int, pos_dim: int, act_dim: int, config=None, horizon: int = HORIZON,
                 frame: str = "world"):
        super().__init__(obs_dim, pos_dim, act_dim, config)
        self.horizon = int(horizon)
        self.frame = check_frame(frame, pos_dim)  # the paths' and the aim's frame (module docstring)
        self.act_dim = self.horizon * pos_dim  # the model's output width, in the base class's names
        self.net = LeanMLP((self.in_dim, *self.config.hidden, self.act_dim), self._rng)
        self.opt = FlatAdam(self.net.num_params, lr=self.config.lr)
        self.norm = RunningNorm(self.in_dim)
        self._y = np.zeros((0, self.act_dim), np.float32)  # (N, h d) scaled displacements

    def _pairs(self, tr: Transitions, good: np.ndarray):
        """``(s_t, mean a_{t..t+h-1})``, ``(p_{t+j} - p_t)_j`` flattened ``(T', h d)`` and ``w_t - p_t`` over
        the rows with ``h`` steps after them in the ``good`` episodes (None: no such row); the base class's
        :meth:`~ForwardServo.add` scales them by the first data's mean ``h``-step displacement."""
        h, d = self.horizon, self.pos_dim
        idx = np.arange(len(tr))  # (T,)
        rows = (episode_end(tr) - idx >= h) & np.isin(tr.episode, good)  # h successors in the episode
        if not rows.any():
            return None
        t = idx[rows]  # (T',)
        ahead = t[:, None] + np.arange(1, h + 1)  # (T', h) rows t+1 .. t+h
        disp = tr.position[ahead] - tr.position[t][:, None, :]  # (T', h, d)
        cs = np.concatenate([np.zeros((1, self.ctrl_dim)), np.cumsum(tr.action.astype(np.float64), 0)])
        mean_a = (cs[t + h] - cs[t]) / h  # (T', act) the mean action of steps t .. t+h-1
        query = (tr.waypoint[t] - tr.position[t]).astype(np.float64)  # (T', d)
        if self.frame == "waypoint":  # each row's path turned into its own waypoint frame at t
            angle = waypoint_angle(tr)[t]  # (T',)
            disp = rotate(disp.transpose(1, 0, 2).reshape(h * len(t), d), np.tile(angle, h))  # (h T', d)
            disp = disp.reshape(h, len(t), d).transpose(1, 0, 2)  # (h T', d) -> (T', h, d)
            query = rotate(query, angle)
        return (np.concatenate([tr.state[t], mean_a], axis=1), disp.reshape(len(t), h * d),  # (T', h, d) -> (T', h d)
                query)

    def predict(self, states: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """``(N, obs)``, ``(N, act)`` -> the displacements ``(N, h, d)`` (float64) with ``actions`` held."""
        out = self.label(states, actions).astype(np.float64) * self.step_scale  # (N, h d)
        return out.reshape(-1, self.horizon, self.pos_dim)  # (N, h d) -> (N, h, d)

    def unexplained(self, trs: list[Transitions]) -> float | None:
        """The share of the variance of ``trs``' paths (in this model's frame) that its predictions leave
        unexplained: 1 is the mean path's error (None: no path in them, or no variance)."""
        xs, ys = [], []
        for tr in trs:
            pairs = self._pairs(tr, np.unique(tr.episode)) if len(tr) else None
            if pairs is not None:
                xs.append(pairs[0])
                ys.append(pairs[1])
        if not xs:
            return None
        x, y = np.concatenate(xs), np.concatenate(ys).astype(np.float64)  # (N, obs + act), (N, h d)
        pred = self.predict(x[:, : self.obs_dim], x[:, self.obs_dim:]).reshape(len(x), -1)  # (N, h, d) -> (N, h d)
        spread = float(((y - y.mean(axis=0)) ** 2).sum())
        return float(((pred - y) ** 2).sum()) / spread if spread > 0 else None


class ShootLabels(ForwardLabels):
    """``a_hat = argmin_a min_j |f_j(s, a) - (w - p)|`` over :func:`candidate_actions` (module docstring);
    input ``w_t - p_t``, or with ``ahead`` the aim ``w_t + ahead (w_t - w_before) - p_t``: past the waypoint along
    the waypoint path (:func:`waypoint_before`), as pure pursuit looks past its waypoint."""

    name = "shoot"
    label_once = True  # costly per row: the clone labels each drawn row once (shaping/cloning.py) ...
    max_rows = 4096  # ... of this many rows drawn from the mean's DAgger set (guides/mechanisms/candidate.py)
    ROWS = 4096  # states per model pass (K x ROWS rows: a few MB, cache-sized)

    def __init__(self, model: ForwardChunk, ahead: float = 0.0, cost: str = "min", hold: bool = False):
        if cost not in SHOOT_COSTS:
            raise ValueError(f"shooting cost must be one of {SHOOT_COSTS}, got {cost!r}")
        self.model, self.ahead, self.cost, self.hold = model, float(ahead), cost, bool(hold)
        self.candidates = candidate_actions(model.ctrl_dim)  # (K, act)

    def inputs(self, tr: Transitions) -> np.ndarray:
        """``(T, d + 1)``: the aim ``w_t - p_t`` (past the waypoint with ``ahead``) in the model's frame, and 1 where
        the waypoint is a goal the body reached and held (:func:`waypoint_held`), else 0."""
        err = np.asarray(tr.waypoint, np.float64) - tr.position  # (T, d) world frame
        before = waypoint_before(tr) if self.ahead or self.hold else None  # (T, d)
        held = waypoint_held(tr, before) if self.hold else np.zeros(len(tr), bool)  # (T,)
        if self.ahead:
            past = self.ahead * (tr.waypoint - before)  # (T, d) the waypoint path's last step
            err += np.where(held[:, None], 0.0, past)  # never past a goal reached and held
        if self.model.frame == "waypoint":
            err = rotate(err, waypoint_angle(tr))  # (T, d) the aim in the model's frame
        return np.concatenate([err, held[:, None]], axis=1).astype(np.float32)  # (T, d + 1)

    def __call__(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        m, A = self.model, self.candidates
        lead = states.shape[:-1]
        s = np.asarray(states, np.float32).reshape(-1, m.obs_dim)  # (N, obs)
        q = np.asarray(inputs, np.float64)
        q = q.reshape(-1, q.shape[-1])  # (N, d) the aim, or (N, d + 1) with the held-goal flag (inputs())
        hold = q[:, m.pos_dim] > 0.5 if q.shape[1] > m.pos_dim else np.zeros(len(q), bool)  # (N,)
        # the waypoint error in the model's scaled output units, float32 like its outputs
        err = (q[:, : m.pos_dim] / (m.step_scale or 1.0)).astype(np.float32)  # (N, d)
        K, n = A.shape[0], s.shape[0]
        out = np.empty((n, m.ctrl_dim), np.float32)
        for i in range(0, n, self.ROWS):
            si, ei = s[i : i + self.ROWS], err[i : i + self.ROWS]
            b = si.shape[0]
            if isinstance(m, ForwardRollout):  # h one-step predictions, in the waypoint space's units
                f = m.paths(np.broadcast_to(si, (K, b, m.obs_dim)).reshape(-1, m.obs_dim), np.repeat(A, b, axis=0))
                f = f.reshape(K, b, m.horizon, m.pos_dim) / (m.step_scale or 1.0)  # (K b, h, d) -> (K, b, h, d)
            else:
                f = m.label(np.broadcast_to(si, (K, b, m.obs_dim)).reshape(-1, m.obs_dim),
                            np.repeat(A, b, axis=0))  # (K b, h d) scaled paths, every candidate held
                f = f.reshape(K, b, m.horizon, m.pos_dim)  # (K b, h d) -> (K, b, h, d)
            f -= ei[None, :, None, :]
            d2 = np.einsum("kbhd,kbhd->kbh", f, f)  # (K, b, h) squared distances to the aim
            # min: the nearest pass (squared); mean: the path's mean distance (a body that must not fly past), also
            # wherever the aim is a goal to hold: a path through it that flies on does not hold it
            held = hold[i : i + b]  # (b,)
            if self.cost == "mean" or held.all():
                miss = np.sqrt(d2).mean(axis=-1)  # (K, b)
            else:
                miss = d2.min(axis=-1)  # (K, b)
                if held.any():  # the mean distance only where needed: this is the labels' hot loop
                    miss[:, held] = np.sqrt(d2[:, held]).mean(axis=-1)
            out[i : i + b] = A[miss.argmin(axis=0)]
        return out.reshape(*lead, m.ctrl_dim)


def check_frame(frame: str, pos_dim: int) -> str:
    """``frame`` if the shooting labels can use it on a ``pos_dim``-dimensional waypoint space (``ValueError``)."""
    if frame not in SHOOT_FRAMES[1:]:
        raise ValueError(f"shooting frame must be one of {SHOOT_FRAMES[1:]}, got {frame!r}")
    if frame == "waypoint" and pos_dim < 2:
        raise ValueError("the shooting labels' waypoint frame needs positions with at least two coordinates")
    return frame


def shoot_model(obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, horizon: int = HORIZON,
                seed: int | None = None, kind: str = "chunk", frame: str = "world") -> ForwardChunk | ForwardRollout:
    """The shooting labels' forward model with M_phi's training settings (``seed``: its own, else M_phi's):
    ``kind`` ``chunk`` (:class:`ForwardChunk`, in ``frame``) or ``rollout`` (``forward_rollout.py``: world frame
    only, its paths are rolled out one predicted step at a time)."""
    if kind not in SHOOT_MODELS:
        raise ValueError(f"shooting model must be one of {SHOOT_MODELS}, got {kind!r}")
    cfg = replace(mphi_cfg, frame="world", targets="one_step", **({} if seed is None else {"seed": seed}))
    if kind == "rollout":
        if frame != "world":
            raise ValueError("the shooting labels' rollout model predicts in the world frame only")
        return ForwardRollout(obs_dim, pos_dim, act_dim, cfg, horizon=horizon)
    return ForwardChunk(obs_dim, pos_dim, act_dim, cfg, horizon=horizon, frame=frame)
