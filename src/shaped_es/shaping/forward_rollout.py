"""A one-step model of the whole observation, rolled out with an action held (the shooting labels' second model).

Why. The shooting labels (``forward_shoot.py``) ask which held action brings the body nearest the waypoint
within ``h`` steps. Their first model, :class:`~shaped_es.shaping.forward_shoot.ForwardChunk`, predicts the
``h``-step displacement from the state and the *mean* of the ``h`` recorded actions: where the recorded actions
vary (members and babblers around a random mean) and the body is far from linear over ``h`` steps, a held action
is not what the data showed. A new user's planar quadrotor (two rotor thrusts, tilt to move sideways): with
the simulator as the model, actions held 16 steps and scored by the path's mean distance drive it to 9.3 of
its controller's 10.0; through the chunk model every horizon stayed near zero action's 0. This model predicts
one step of everything the policy sees, ``f(s_t, a_t) -> (s_{t+1} - s_t, p_{t+1} - p_t)``, and a held action's
path is ``h`` of its steps, each fed the last prediction: fitted on the label probe's 2,100 steps (with more
Adam steps than the run's models take) its held-action labels drove the quadrotor to 9.4
(``docs/benchmarks/shoot_rollout_v19``). It needs an observation that says where the body is going (a Markov
state); the chunk model does not.

Each output is scaled by 4 x its first data's mean absolute change (the displacement by
:class:`~shaped_es.shaping.forward_servo.ForwardServo`'s step scale), into the output tanh's range. Hand-written,
as the other forward models: no library fits and rolls out a waypoint-space model with our kernels and data parts.
"""

from __future__ import annotations

import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping.forward_servo import TARGET_SCALE, ForwardServo
from shaped_es.shaping.inverse_dynamics import RunningNorm
from shaped_es.shaping.lean_mlp import FlatAdam, LeanMLP


class ForwardRollout(ForwardServo):
    """``f(s, a) -> (s' - s, p' - p)`` and its ``h``-step rollouts (module docstring); the servo's data set,
    training, checkpoint and data parts with the observation's change as more outputs."""

    def __init__(self, obs_dim: int, pos_dim: int, act_dim: int, config=None, horizon: int = 4):
        super().__init__(obs_dim, pos_dim, act_dim, config)
        self.horizon = int(horizon)
        self.act_dim = obs_dim + pos_dim  # the model's output width, in the base class's names
        self.net = LeanMLP((self.in_dim, *self.config.hidden, self.act_dim), self._rng)
        self.opt = FlatAdam(self.net.num_params, lr=self.config.lr)
        self.norm = RunningNorm(self.in_dim)
        self._y = np.zeros((0, self.act_dim), np.float32)  # (N, obs + d) scaled changes
        self.obs_scale = np.zeros(obs_dim)  # (obs,) 4 x the first data's mean |s' - s| per entry (0: no data)

    def _fix_scales(self, dp: np.ndarray) -> None:
        change = np.abs(dp[:, : self.obs_dim]).mean(axis=0)  # (obs,)
        self.obs_scale = np.where(change > 0, TARGET_SCALE * change, 1.0)

    def _target_scale(self):
        return np.concatenate([self.obs_scale, np.full(self.pos_dim, self.step_scale or 1.0)])  # (obs + d,)

    def _pairs(self, tr: Transitions, good: np.ndarray):
        """``(s_t, a_t)``, ``(s_{t+1} - s_t, p_{t+1} - p_t)`` ``(T', obs + d)`` and ``w_t - p_t`` over the steps of the
        ``good`` episodes that have a successor (None: no such step)."""
        mask, nxt = tr.next_position()  # (T,), (T, d)
        mask &= np.isin(tr.episode, good)
        if not mask.any():
            return None
        t = np.flatnonzero(mask)  # (T',)
        change = np.concatenate([tr.state[t + 1] - tr.state[t], nxt[t] - tr.position[t]], axis=1)  # (T', obs + d)
        return (np.concatenate([tr.state[t], tr.action[t]], axis=1), change, tr.waypoint[t] - tr.position[t])

    def step(self, states: np.ndarray, actions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """One predicted step: ``(N, obs)``, ``(N, act)`` -> ``(s', p' - p)``, ``(N, obs)`` float32 and ``(N, d)``."""
        out = self.label(states, actions).astype(np.float64) * self._target_scale()  # (N, obs + d)
        return (states + out[:, : self.obs_dim]).astype(np.float32), out[:, self.obs_dim:]

    def paths(self, states: np.ndarray, actions: np.ndarray) -> np.ndarray:
        """``(N, obs)``, ``(N, act)`` -> the displacements ``(N, h, d)`` (float64) with ``actions`` held ``h``
        steps, each step fed the last one's predicted observation."""
        s = np.asarray(states, np.float32)
        p = np.zeros((s.shape[0], self.pos_dim))  # (N, d)
        out = np.empty((s.shape[0], self.horizon, self.pos_dim))  # (N, h, d)
        for j in range(self.horizon):
            s, dp = self.step(s, actions)
            p += dp
            out[:, j] = p
        return out

    def state_dict(self, with_training: bool = True, with_data: bool = True) -> dict[str, np.ndarray]:
        out = super().state_dict(with_training, with_data)
        out["rollout/obs_scale"] = np.asarray(self.obs_scale, np.float64)
        return out

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        super().load_state_dict(state)
        scale = np.asarray(state.get("rollout/obs_scale", np.zeros(self.obs_dim)), np.float64).reshape(-1)
        if scale.shape != (self.obs_dim,) or not np.isfinite(scale).all() or (scale < 0).any():
            raise ValueError(f"rollout model's observation scales have shape {scale.shape} or bad values, "
                             f"expected {self.obs_dim} finite non-negative numbers")
        self.obs_scale = scale
