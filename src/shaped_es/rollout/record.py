"""The recorded members' steps of a rollout: each step's rows kept as the episodes run (``_Recorder``),
built into one block per task (``data.PackedTransitions``), and the env's waypoint controller whose
action a recorded step keeps as ``Transitions.expert`` (``RolloutTask.expert``).

The rollout loops (``rollout/batched.py``, ``rollout/gym_loop.py``) call these; nothing here steps an env.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from shaped_es.data import PackedTransitions, Transitions
from shaped_es.env_probe import EnvSpecError
from shaped_es.envs.core import CONTROLLER_HOOK


class _Recorder:
    """Per-step rows of the recorded members written into preallocated float32 buffers ``(T, B_r, ...)``
    (grown by doubling when the horizon is unknown), gathered into one block of rows at the end.
    Episodes run in lock-step and stay dead once done, so episode ``b`` is rows ``0 .. len_b - 1`` of its
    column. ``B_r``: the recorded members' episodes (``RolloutTask.recorded``)."""

    def __init__(self, task, capacity: int = 256):  # task: a RolloutTask
        self.task, self.t, self.capacity = task, 0, max(1, int(capacity))
        E = task.seeds.shape[1]
        mask = task.recorded()  # (m,)
        self.rows = np.flatnonzero(mask)  # (m_r,) task rows of the recorded members
        self.cols = None if mask.all() else (self.rows[:, None] * E + np.arange(E)).reshape(-1)  # (m_r*E,)
        self.buf: list[np.ndarray] | None = None  # obs, pos, wp, act, rew, alive[, expert]: (cap, B_r, ...)

    def add(self, obs, pos, wp, act, rew, alive, expert=None):
        rows = (obs, pos, wp, act, rew, alive) + (() if expert is None else (expert,))
        if self.cols is not None:
            rows = tuple(np.asarray(x)[self.cols] for x in rows)  # (B, ...) -> (B_r, ...)
        if self.buf is None:
            self.buf = [np.zeros((self.capacity, *np.shape(x)), bool if i == 5 else np.float32)
                        for i, x in enumerate(rows)]
        if self.t == self.buf[0].shape[0]:  # grow: double the time axis
            self.buf = [np.concatenate([b, np.zeros_like(b)]) for b in self.buf]
        for b, x in zip(self.buf, rows):
            b[self.t] = x
        self.t += 1

    def build(self) -> PackedTransitions | None:
        """The recorded members' steps as one block (``data.PackedTransitions``): one gather per column,
        rows in (member, episode, step) order, as each member's :class:`Transitions` holds them."""
        E = self.task.seeds.shape[1]
        if self.buf is None or self.t == 0 or self.rows.size == 0:
            return None
        obs, pos, wp, act, rew, alive, *ex = (b[: self.t] for b in self.buf)  # (T, B_r, ...)
        # episode b (column b = j * E + e) is rows 0 .. len_b - 1 of its column (dead once done): nonzero
        # of the transposed mask lists its (b, t) pairs b-major, so the rows come in (member, episode, step)
        # order
        b_idx, t_idx = np.nonzero(alive.T)  # (N,), (N,) with alive.T (B_r, T)
        lens = alive.sum(axis=0)  # (B_r,) steps each recorded episode took
        per_member = lens.reshape(-1, E).sum(axis=1)  # (B_r,) -> (m_r, E) -> (m_r,)
        flat = t_idx * alive.shape[1] + b_idx  # (N,) row of (t, b) in the (T * B_r, ...) view

        def take(x):  # (T, B_r, ...) -> (T * B_r, ...) -> (N, ...)
            return x.reshape(x.shape[0] * x.shape[1], *x.shape[2:]).take(flat, axis=0)
        rows = Transitions(
            generation=self.task.generation, member=-1,
            episode=(b_idx % E).astype(np.int32), step=t_idx.astype(np.int32),
            state=take(obs), position=take(pos), waypoint=take(wp), action=take(act), reward=take(rew),
            expert=take(ex[0]) if ex else None,
        )
        members = np.asarray(self.task.members)[self.rows].astype(np.int64)  # (m_r,)
        return PackedTransitions(rows, members, np.concatenate([[0], np.cumsum(per_member)]).astype(np.int64))


def _controller(task, owner):
    """The env's waypoint controller (``envs/core.py`` hook) of ``owner`` (a core or an env), or one
    clear error if the task (a ``RolloutTask``) asks for it and the env has none."""
    hook = getattr(owner, CONTROLLER_HOOK, None)
    if not callable(hook):
        raise EnvSpecError(f"env {task.env_id!r} offers no {CONTROLLER_HOOK}(...) (shaping.labels=controller "
                           f"needs one; see the README's environment contract)")
    return hook


def _join_episodes(generation: int, member: int, eps: list[tuple[int, Transitions]]) -> Transitions:
    """One member's recorded episodes ``(episode index, Transitions)``, run one after another, as one
    :class:`Transitions` in episode order (an optional column is None if any episode lacks it)."""
    per_step = [f.name for f in dataclasses.fields(Transitions)
                if f.name not in ("generation", "member", "episode")]
    fields = {name: None if any(getattr(t, name) is None for _, t in eps)  # an optional column
              else np.concatenate([getattr(t, name) for _, t in eps]) for name in per_step}
    return Transitions(generation=generation, member=member,
                       episode=np.concatenate([np.full(len(t), e, np.int32) for e, t in eps]),
                       **fields)
