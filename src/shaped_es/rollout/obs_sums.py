"""Each episode's observation count, sum and sum of squares (``RolloutTask.obs_stats``, es.obs_norm),
summed so that a member's sums do not depend on the batch or task its episodes ran in.
"""

from __future__ import annotations

import numpy as np


def _sum_in_order(parts: list[np.ndarray]) -> np.ndarray:
    """``parts[0] + parts[1] + ...`` left to right (the same rounding whatever batch they came from)."""
    acc = np.array(parts[0], dtype=np.float64, copy=True)
    for p in parts[1:]:
        acc = acc + p
    return acc


class _ObsSums:
    """Per episode column: the count, sum and sum of squares (float64) of the observations the policy saw
    while the episode ran (elementwise accumulation over steps, so a column's sums do not depend on the
    batch it ran in)."""

    def __init__(self, B: int):
        self.count = np.zeros(B)  # (B,)
        self.total: np.ndarray | None = None  # (B, obs)
        self.squares: np.ndarray | None = None  # (B, obs)

    def add(self, obs: np.ndarray, alive: np.ndarray) -> None:
        x = np.asarray(obs, dtype=np.float32).astype(np.float64)  # what the policy sees, in float64
        x = np.where(alive[:, None], x, 0.0)  # (B, obs)
        if self.total is None:
            self.total, self.squares = np.zeros_like(x), np.zeros_like(x)
        self.count += alive
        self.total += x
        self.squares += x * x

    def per_member(self, m: int, E: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(count (m,), sum (m, obs), sum of squares (m, obs)): each member's E episodes summed in order."""
        d = 0 if self.total is None else self.total.shape[1]
        total = np.zeros((m * E, d)) if self.total is None else self.total
        squares = np.zeros((m * E, d)) if self.squares is None else self.squares
        return tuple(_sum_in_order([x.reshape(m, E, *x.shape[1:])[:, e] for e in range(E)])
                     for x in (self.count, total, squares))
