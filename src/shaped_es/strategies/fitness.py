"""Small pure functions shared by the strategies: fitness shaping, antithetic sampling, weight decay.

Everything here maximizes: a larger fitness is better.

- :func:`centered_ranks` -- the paper's shaping (Lekkala & Itti, Sec. Experiments: "the fitness/reward
  values are rank transformed to the range of -1 to +1"): lowest -> -1, highest -> +1, linear in rank.
- :func:`antithetic` / :func:`antithetic_gradient` -- mirrored sampling and the finite-difference
  estimator of Eq. (4) (written for ascent).
- :func:`l2_decay` (on the gradient, Vanilla/Guided ES) and :func:`l2_fitness_penalty` (on the fitness,
  the CMA-ES baseline's weight decay of 0.05, as in estool).
"""

from __future__ import annotations

import numpy as np

SHAPINGS = ("rank", "none")


def centered_ranks(fitness: np.ndarray) -> np.ndarray:
    """Ranks of ``fitness`` mapped linearly onto [-1, 1]: the lowest gets -1, the highest +1.

    Ties share the mean of the ranks they span (deterministic and independent of the order of the
    members), so equal fitness always gets equal shaped fitness -- in particular an antithetic pair with
    equal returns contributes nothing to the gradient. All-equal fitness gives all zeros.
    """
    f = np.asarray(fitness, dtype=np.float64).ravel()  # (N,)
    n = f.shape[0]
    if n == 0:
        return f.copy()
    if n == 1:
        return np.zeros(1)
    if np.isnan(f).any():
        raise ValueError("centered_ranks: fitness contains NaN")
    _, inverse, counts = np.unique(f, return_inverse=True, return_counts=True)  # sorted unique values
    first = np.cumsum(counts) - counts  # (U,) rank of the first member of each tie group
    mean_rank = first + (counts - 1) / 2.0  # (U,) 0-based mean rank of each group
    ranks = mean_rank[inverse.ravel()]  # (N,)
    return 2.0 * ranks / (n - 1) - 1.0


def identity(fitness: np.ndarray) -> np.ndarray:
    """No shaping: the raw fitness as float64 (a copy)."""
    return np.array(fitness, dtype=np.float64).ravel()


def shape_fitness(fitness: np.ndarray, method: str) -> np.ndarray:
    """Apply the named shaping (``"rank"``: :func:`centered_ranks`, ``"none"``: :func:`identity`)."""
    if method == "rank":
        return centered_ranks(fitness)
    if method == "none":
        return identity(fitness)
    raise ValueError(f"unknown fitness_shaping {method!r}; choose one of {SHAPINGS}")


def antithetic(z: np.ndarray) -> np.ndarray:
    """Mirrored directions ``[z; -z]``: row ``i`` and row ``i + P`` are exact negatives, so they sum to 0."""
    z = np.asarray(z)
    return np.concatenate([z, -z], axis=0)  # (2P, n)


def antithetic_gradient(z: np.ndarray, shaped: np.ndarray, sigma: float) -> np.ndarray:
    """Ascent direction of Eq. (4) from mirrored samples ``mu +/- sigma * z_i``.

    ``g = 1 / (2 sigma P) * sum_i z_i (F+_i - F-_i)`` where ``shaped`` holds ``[F+_1..P, F-_1..P]`` and
    ``z`` (P, n) are the directions in units of sigma (``eps_i = sigma * z_i``). This equals the paper's
    ``beta / (2 sigma^2 P) * sum_i eps_i [F(mu + eps_i) - F(mu - eps_i)]`` with ``beta = 1`` (the paper's
    beta and gamma are both absorbed into the optimizer's learning rate). The paper writes the update
    with a minus sign for a loss; here F is a reward and we ascend.
    """
    z = np.asarray(z, dtype=np.float64)
    P = z.shape[0]
    s = np.asarray(shaped, dtype=np.float64).ravel()
    if s.shape[0] != 2 * P:
        raise ValueError(f"antithetic_gradient: expected {2 * P} fitness values, got {s.shape[0]}")
    diff = s[:P] - s[P:]  # (P,) F+_i - F-_i
    return (diff @ z) / (2.0 * sigma * P)  # (n,)  Eq. (4)


def l2_decay(grad: np.ndarray, mean: np.ndarray, weight_decay: float) -> np.ndarray:
    """Ascent direction of ``F(mu) - weight_decay / 2 * ||mu||^2``: ``grad - weight_decay * mu``."""
    if weight_decay == 0.0:
        return np.asarray(grad, dtype=np.float64)
    return np.asarray(grad, dtype=np.float64) - weight_decay * np.asarray(mean, dtype=np.float64)


def l2_fitness_penalty(fitness: np.ndarray, params: np.ndarray, weight_decay: float) -> np.ndarray:
    """CMA-ES weight decay (estool's habit): ``fitness_i - weight_decay * mean(x_i ** 2)``."""
    f = np.asarray(fitness, dtype=np.float64).ravel()  # (N,)
    X = np.asarray(params, dtype=np.float64)  # (N, n)
    if weight_decay == 0.0:
        return f
    return f - weight_decay * np.mean(X * X, axis=1)  # (N,)
