"""Every member's data set ``D_i`` as row spans of shared per-generation blocks (no per-member copies),
and the gather of the minibatch rows behaviour cloning draws from them (``cloning.clone_sampled``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from shaped_es.shaping import kernels


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

    def subsample(self, rows: int, rng: np.random.Generator) -> "MemberRows":
        """One member's data set (``P = 1``) cut to ``rows`` rows drawn without replacement (in their
        order), as one block; itself when it has no more. For a label source that costs per row."""
        if self.spans.shape[0] != 1:
            raise ValueError(f"subsample takes one member's rows, got {self.spans.shape[0]} members")
        n = int(self.lengths()[0])
        if n <= rows:
            return self
        pos = np.sort(rng.choice(n, size=rows, replace=False))[None, None, :]  # (1, 1, rows)
        S, Q = self.gather(pos)  # (1, 1, rows, obs), (1, 1, rows, d)
        return MemberRows.from_lists([S[0, 0]], [Q[0, 0]])

    def gather(self, pos: np.ndarray, out_states: np.ndarray | None = None):
        """Rows at per-member positions ``pos`` ``(draws, P, B)`` (into ``D_i``, oldest first) ->
        states ``(draws, P, B, obs)``, queries ``(draws, P, B, d)``. With ``out_states`` (float32, that
        shape) the states are written there and only the queries are returned."""
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
        flat_b, flat_l = block.reshape(-1), local.reshape(-1)  # (draws*P*B,)
        if out_states is None:
            S = np.zeros((flat_b.size, obs), np.float32)  # (draws * P * B, obs); no data: zeros
        else:
            if out_states.shape != (*pos.shape, obs) or not out_states.flags.c_contiguous:
                raise ValueError(f"out_states must be C-contiguous {(*pos.shape, obs)}, got {out_states.shape}")
            S = out_states.reshape(flat_b.size, obs)  # a view: (draws, P, B, obs) -> (draws*P*B, obs)
            S[flat_b < 0] = 0.0
        Q = np.zeros((flat_b.size, d), np.float32)  # (draws * P * B, d)
        # per block: one np.take of its drawn rows, scattered into place (no concatenation of the
        # blocks, which copied every generation's whole data set for each gather)
        for b in range(len(self.states)):
            if kernels.ENABLED and self.states[b].dtype == np.float32 and self.queries[b].dtype == np.float32:
                for src, dst in ((self.states[b], S), (self.queries[b], Q)):
                    if src.shape[1]:
                        kernels.take_block_rows(np.ascontiguousarray(src), flat_b, flat_l, b, dst)
                continue
            sel = np.flatnonzero(flat_b == b)  # the draws that fall in block b (no sort: 5x cheaper)
            if sel.size:
                S[sel] = np.take(self.states[b], flat_l[sel], axis=0)
                Q[sel] = np.take(self.queries[b], flat_l[sel], axis=0)
        if out_states is not None:
            return Q.reshape(*pos.shape, d)
        return S.reshape(*pos.shape, obs), Q.reshape(*pos.shape, d)
