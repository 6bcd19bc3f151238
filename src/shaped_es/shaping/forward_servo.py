"""Servo labels: a learned forward model's damped servo toward the waypoint (a rival label variant).

Why. On a torque-driven arm no inverse of the dynamics gives labels that pay, not even the simulator's exact
one (``docs/shaped-results.md``, "Action-chunk labels"): a one-step displacement is almost all velocity,
so the inverse asks for saturated torques. The env's controller, whose labels solve the Reacher 10/10, is
a damped velocity servo with small torques. This is its learned, body-agnostic analogue:

- a forward model ``f(s_t, a_t) -> p_{t+1} - p_t`` (one step, waypoint space), fitted on the recorded
  steps like ``M_phi`` (the same lean MLP, kernels and data parts; inputs and targets swapped);
- its action sensitivity ``G(s) = df/da`` at ``a = 0`` by finite differences, ``(d, act)``, scaled to unit
  Frobenius norm (its direction, not its size, which a one-step model gets wrong on a second-order body);
- its drift ``f(s, 0)``: the step the body takes with no action, i.e. its velocity;
- the label: a transpose servo on the waypoint error, damped by the drift,

      a_hat = clip(k * G_hat(s)^T ((w_t - p_t) - c * f(s_t, 0)) / q, -1, 1)

  with ``q`` the median query distance ``|w - p|`` of the first data (scale-free gains), ``k`` =
  ``servo_gain``, ``c`` = ``servo_damping``.

Measured offline (``docs/benchmarks/labels_servo/``; 20 episodes driven by the labels of a model fitted
on 5 generations of rollouts and babbling): ReacherWay-v0 -7.2 at ``k = 1`` (-6.6 at 0.5; its controller
-5.7, zero torque -10.8, the best M_phi variant about -20), UR5Reach-v0 72 (M_phi's best 48), the points
8.5-8.7; useless on the unicycle, the car and the swimmer (one step of a non-holonomic body or a swimmer
shows no turning or undulation: ``G``'s transpose cannot ask for them). The run keeps it only where its
candidate wins (``guides/rival.py``). Hand-written: no library fits a control servo through a learned
forward model.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping.inverse_dynamics import InverseDynamics, RunningNorm
from shaped_es.shaping.labels import LabelSource
from shaped_es.shaping.lean_mlp import FlatAdam, LeanMLP
from shaped_es.shaping.mphi_inputs import kept_episodes

TARGET_SCALE = 4.0  # targets are (p_{t+1} - p_t) / (4 x the first data's mean step): inside tanh's range
FD_STEP = 0.5  # the finite-difference step of G in action units


class ForwardServo(InverseDynamics):
    """The forward model ``f(s, a) -> p_{t+1} - p_t``: :class:`InverseDynamics`' data set, training,
    checkpoint and data parts with inputs ``(s_t, a_t)`` and targets the scaled one-step displacement.

    In the base class's names ``act_dim`` is the model's output width (the waypoint space's ``d``) and
    ``query_dim`` its second input's (the action's); ``ctrl_dim`` is the action dimension."""

    frame = "world"  # the frame its displacements are in (the chunk model can also predict in the waypoint frame)

    def __init__(self, obs_dim: int, pos_dim: int, act_dim: int, config=None):
        super().__init__(obs_dim, pos_dim, act_dim, config)
        self.step_change = False  # M_phi's extra input: not a forward model's
        self.ctrl_dim = act_dim
        self.act_dim, self.query_dim, self.in_dim = pos_dim, act_dim, obs_dim + act_dim
        self.net = LeanMLP((self.in_dim, *self.config.hidden, pos_dim), self._rng)
        self.opt = FlatAdam(self.net.num_params, lr=self.config.lr)
        self.norm = RunningNorm(self.in_dim)
        self._x = np.zeros((0, self.in_dim), np.float32)  # (N, obs + act) raw inputs
        self._y = np.zeros((0, pos_dim), np.float32)  # (N, d) scaled displacements
        self.step_scale = 0.0  # 4 x the first data's mean one-step displacement (0: no data yet)
        self.query_scale = 0.0  # the first data's median |w_t - p_t|

    def _check(self, tr: Transitions) -> None:
        got = (tr.state.shape[1], tr.position.shape[1], tr.action.shape[1])
        if got != (self.obs_dim, self.pos_dim, self.ctrl_dim):
            raise ValueError(f"transitions have (obs, pos, act) dims {got}, model expects "
                             f"{(self.obs_dim, self.pos_dim, self.ctrl_dim)}")

    def add(self, transitions_list: Sequence[Transitions]) -> dict[str, float]:
        """Aggregate :meth:`_pairs` ``(s_t, a_t) -> displacement / step_scale`` of episodes passing the return
        filter; ``step_scale`` and ``query_scale`` are fixed by the first data."""
        xs, ys, qs, episodes, kept = [], [], [], 0, 0
        for tr in transitions_list:
            if len(tr) == 0:
                continue
            self._check(tr)
            eps, good = kept_episodes(tr, self.config.min_return, self.config.filter)
            episodes, kept = episodes + eps.size, kept + good.size
            pairs = self._pairs(tr, good)
            if pairs is not None:
                for out, v in zip((xs, ys, qs), pairs):
                    out.append(v)
        x = np.concatenate(xs).astype(np.float32) if xs else self._x[:0]
        dp = np.concatenate(ys).astype(np.float64) if ys else np.zeros((0, self.act_dim))  # (N, out)
        with self._lock:
            if self.step_scale == 0.0 and dp.shape[0]:  # fixed by the first data (checkpointed)
                step = float(np.linalg.norm(dp[:, -self.pos_dim:], axis=1).mean())  # the last displacement's
                self.step_scale = TARGET_SCALE * step if step > 0 else 1.0
                self.query_scale = float(np.median(np.linalg.norm(np.concatenate(qs), axis=1))) or 1.0
                self._fix_scales(dp)
            y = np.clip(dp / self._target_scale(), -0.99, 0.99).astype(np.float32)  # (N, out)
            self.norm.update(x)
            self._append(x, y)
            size = self.dataset_size
        return {"episodes": float(episodes), "kept_episodes": float(kept),
                "kept_fraction": kept / episodes if episodes else 0.0,
                "added": float(x.shape[0]), "dataset_size": float(size)}

    def _fix_scales(self, dp: np.ndarray) -> None:
        """Further target scales fixed by the first data ``dp`` ``(N, out)`` (none here: one displacement)."""

    def _target_scale(self):
        """What the targets are divided by: the step scale (a model with other outputs: one per output)."""
        return self.step_scale or 1.0

    def _pairs(self, tr: Transitions, good: np.ndarray):
        """One recording's ``(inputs (T', obs + act), displacements (T', d), queries w - p (T', d))`` over
        the steps of the ``good`` episodes that have a successor (None: no such step)."""
        mask, nxt = tr.next_position()  # (T,), (T, d)
        mask &= np.isin(tr.episode, good)
        if not mask.any():
            return None
        return (np.concatenate([tr.state[mask], tr.action[mask]], axis=1), (nxt - tr.position)[mask],
                tr.waypoint[mask] - tr.position[mask])

    def predict(self, states: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """``f(s, a)``: ``(N, obs)``, ``(N, act)`` -> the one-step displacements ``(N, d)`` (float64)."""
        return self.label(states, actions).astype(np.float64) * self.step_scale

    def state_dict(self, with_training: bool = True, with_data: bool = True) -> dict[str, np.ndarray]:
        out = super().state_dict(with_training, with_data)
        out["servo/scales"] = np.array([self.step_scale, self.query_scale], np.float64)
        return out

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        super().load_state_dict(state)
        scales = np.asarray(state.get("servo/scales", np.zeros(2)), np.float64).reshape(-1)
        if scales.shape != (2,) or not np.isfinite(scales).all() or (scales < 0).any():
            raise ValueError(f"servo scales {scales.tolist()} are not two finite non-negative numbers")
        self.step_scale, self.query_scale = float(scales[0]), float(scales[1])


class ForwardLabels(LabelSource):
    """Labels read off a forward model ``self.model`` (this servo, ``forward_shoot.ShootLabels``): ready once
    it has trained on data that fixed its scales; input the world-frame waypoint error ``w_t - p_t``."""

    model: ForwardServo

    @property
    def ready(self) -> bool:
        return self.model.iterations > 0 and self.model.step_scale > 0

    def inputs(self, tr: Transitions) -> np.ndarray:
        return np.asarray(tr.waypoint - tr.position, np.float32)  # (T, d) world frame


class ServoLabels(ForwardLabels):
    """``a_hat = clip(k G_hat(s)^T ((w - p) - c f(s, 0)) / q, -1, 1)`` (module docstring); input ``w_t - p_t``."""

    name = "servo"

    def __init__(self, model: ForwardServo, gain: float = 1.0, damping: float = 3.0):
        self.model, self.gain, self.damping = model, float(gain), float(damping)

    def __call__(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        m = self.model
        lead = states.shape[:-1]
        s = np.asarray(states, np.float32).reshape(-1, m.obs_dim)  # (N, obs)
        err = np.asarray(inputs, np.float64).reshape(-1, m.pos_dim)  # (N, d)
        n, k = s.shape[0], m.ctrl_dim
        # the zero action and the k finite-difference actions in one pass: (k + 1) N rows
        acts = np.zeros((k + 1, n, k), np.float32)  # (k + 1, N, act)
        acts[1:] += FD_STEP * np.eye(k, dtype=np.float32)[:, None, :]
        f = m.predict(np.broadcast_to(s, (k + 1, n, m.obs_dim)).reshape(-1, m.obs_dim),
                      acts.reshape(-1, k)).reshape(k + 1, n, m.pos_dim)  # (k + 1, N, d)
        drift = f[0]  # (N, d) the step with no action
        G = np.moveaxis(f[1:] - drift, 0, -1) / FD_STEP  # (k, N, d) -> (N, d, act)
        G /= np.maximum(np.linalg.norm(G, axis=(1, 2), keepdims=True), 1e-12)
        e = (err - self.damping * drift) / (m.query_scale or 1.0)  # (N, d)
        a = self.gain * np.einsum("nda,nd->na", G, e)  # (N, act) G_hat^T e
        return np.clip(a, -1.0, 1.0).astype(np.float32).reshape(*lead, k)


def servo_model(obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, seed: int) -> ForwardServo:
    """The forward model with M_phi's training settings (its own seed; world frame, one-step targets)."""
    return ForwardServo(obs_dim, pos_dim, act_dim, replace(mphi_cfg, frame="world", targets="one_step", seed=seed))
