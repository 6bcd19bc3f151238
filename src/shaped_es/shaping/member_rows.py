"""Every member's data set ``D_i`` as row spans of shared per-generation blocks (no per-member copies),
and the gather of the minibatch rows behaviour cloning draws from them (``cloning.clone_sampled``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np


@dataclass
class MemberRows:
    """Every member's data set ``D_i`` as row spans of shared blocks (one block per generation, oldest
    first): member ``i``'s rows are ``block_b[spans[i, b, 0] : spans[i, b, 1]]`` for ``b`` in order. No
    per-member copies: draws are mapped to (block, row) and gathered once per block."""

    states: list[np.ndarray]  # per block (N_b, obs) float32
    queries: list[np.ndarray]  # per block (N_b, d) float32, M_phi's raw queries w_t - p_t
    spans: np.ndarray  # (P, n_blocks, 2) int64 start, stop

    @classmethod
    def from_lists(cls, states: Sequence[np.ndarray], queries: Sequence[np.ndarray]) -> "MemberRows":
        """Per-member arrays ``(T_i, obs)``, ``(T_i, d)`` (oldest first) as one block."""
        lens = np.array([len(x) for x in states], np.int64)
        if len(queries) != len(states) or any(len(q) != n for q, n in zip(queries, lens)):
            raise ValueError("each member needs as many queries as states")
        ends = np.cumsum(lens)
        spans = np.stack([ends - lens, ends], axis=1)[:, None, :]  # (P, 1, 2)
        d = next((np.asarray(q).shape[-1] for q in queries if len(q)), 0)
        obs = next((np.asarray(x).shape[-1] for x in states if len(x)), 0)
        S = np.concatenate([np.asarray(x, np.float32).reshape(-1, obs) for x in states]) if len(states) else \
            np.zeros((0, obs), np.float32)
        Q = np.concatenate([np.asarray(x, np.float32).reshape(-1, d) for x in queries]) if len(queries) else \
            np.zeros((0, d), np.float32)
        return cls([S], [Q], spans)

    def lengths(self) -> np.ndarray:
        return (self.spans[..., 1] - self.spans[..., 0]).sum(axis=1)  # (P,)

    def newest(self, max_samples: int) -> "MemberRows":
        """Each member keeps only its newest ``max_samples`` rows (dropped from its oldest blocks)."""
        if max_samples <= 0:
            return self
        spans = self.spans.copy()
        lens = spans[..., 1] - spans[..., 0]  # (P, nb)
        after = np.cumsum(lens[:, ::-1], axis=1)[:, ::-1] - lens  # (P, nb) rows in newer blocks
        keep = np.clip(max_samples - after, 0, lens)  # (P, nb) rows kept per block (its newest)
        spans[..., 0] = spans[..., 1] - keep
        return MemberRows(self.states, self.queries, spans)

    def gather(self, pos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows at per-member positions ``pos`` ``(draws, P, B)`` (into ``D_i``, oldest first) ->
        states ``(draws, P, B, obs)``, queries ``(draws, P, B, d)``."""
        P = self.spans.shape[0]
        lens = self.spans[..., 1] - self.spans[..., 0]  # (P, nb)
        ends = np.cumsum(lens, axis=1)  # (P, nb)
        block = np.full(pos.shape, -1, np.int64)  # -1: a member without data (rows left as zeros)
        local = np.zeros(pos.shape, np.int64)
        for i in np.flatnonzero(ends[:, -1] if ends.shape[1] else np.zeros(P)):
            b = np.searchsorted(ends[i], pos[:, i], side="right")  # (draws, B) block of each draw
            b = np.minimum(b, lens.shape[1] - 1)
            block[:, i] = b
            local[:, i] = self.spans[i, b, 0] + pos[:, i] - (ends[i, b] - lens[i, b])
        obs, d = self.states[0].shape[1], self.queries[0].shape[1]
        # one np.take from the stacked blocks (concatenate + take: 3x faster than per-block masks)
        sizes = np.array([len(x) for x in self.states], np.int64)
        first = np.concatenate([[0], np.cumsum(sizes)[:-1]])  # (nb,) first row of each block
        rows = np.where(block >= 0, first[np.maximum(block, 0)] + local, 0).reshape(-1)  # (draws*P*B,)
        S_all, Q_all = np.concatenate(self.states), np.concatenate(self.queries)
        if S_all.shape[0] == 0:
            return (np.zeros((*pos.shape, obs), np.float32), np.zeros((*pos.shape, d), np.float32))
        S = np.take(S_all, rows, axis=0)  # (draws * P * B, obs)
        Q = np.take(Q_all, rows, axis=0)  # (draws * P * B, d)
        empty = (block < 0).reshape(-1)
        if empty.any():  # members without data: zeros
            S[empty], Q[empty] = 0.0, 0.0
        return S.reshape(*pos.shape, obs), Q.reshape(*pos.shape, d)
