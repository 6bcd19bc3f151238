"""Guided ES (Maheswaranathan et al. 2019): search elongated along a surrogate-gradient subspace.

Lekkala & Itti, Eq. (5) (after Maheswaranathan et al. 2019)::

    Sigma = alpha / n * I_n + (1 - alpha) / k * U U^T

with ``U`` (n, k) an orthonormal basis (QR) of the k surrogate gradients. We scale Sigma by n so its
trace equals Vanilla-ES's and sigma means the same for both::

    eps = sigma * (sqrt(alpha) * z_n + sqrt((1 - alpha) * n / k) * U z_k),  z_n ~ N(0, I_n), z_k ~ N(0, I_k)
    Cov(eps) = sigma^2 * (alpha * I_n + (1 - alpha) * n / k * U U^T)

The gradient estimator is the antithetic one of Vanilla-ES with ``z = eps / sigma`` (Maheswaranathan et
al. 2019, Algorithm 1: ``beta / (2 sigma^2 P) * sum_i eps_i (F+_i - F-_i)``), then the same optimizer
step. ``z_n`` is drawn first from the generation's RNG, so with no subspace (or ``alpha = 1``) every
number equals :class:`VanillaES`'s for the same seed.

Surrogate semantics: ``guide(G)`` sets the subspace used by the NEXT ``ask`` only;
``tell(fitness, surrogate=G)`` is ``tell(fitness)`` then ``guide(G)``; a ``tell`` without a surrogate
clears the subspace. The trainer calls ``tell(fitness)``, computes G from the new mean (Eq. (6):
``Delta = (Theta* - mu_{g+1}) / eta``), then ``guide(G)``.
"""

from __future__ import annotations

import numpy as np

from shaped_es.strategies.vanilla import VanillaES

RANK_RTOL = 1e-6  # a surrogate whose distance to the span of the previous ones is below this share
# of its own norm adds no direction and is dropped


def orthonormal_basis(G: np.ndarray, rtol: float = RANK_RTOL) -> np.ndarray:
    """Orthonormal basis U (n, r) of the span of the rows of G (k, n), r = effective rank <= min(k, n).

    Reduced QR of ``G^T``. A column whose ``|R_jj|`` (its distance to the span of the columns before
    it) is at most ``rtol * ||g_j||`` is linearly dependent: it is dropped and the QR redone, so every
    column of U comes from an independent surrogate. Zero rows are dropped; at most n columns are kept.
    """
    G = np.asarray(G, dtype=np.float64)
    if G.ndim == 1:
        G = G[None, :]  # (1, n)
    n = G.shape[1]
    A = G.T[:, np.linalg.norm(G, axis=1) > 0]  # (n, k') non-zero surrogates as columns
    while A.shape[1] > 0:
        Q, R = np.linalg.qr(A, mode="reduced")  # Q (n, m), R (m, k'), m = min(n, k')
        m = Q.shape[1]
        d = np.abs(np.diagonal(R))  # (m,)
        bad = np.flatnonzero(d <= rtol * np.linalg.norm(A[:, :m], axis=0))
        if bad.size == 0:
            return Q  # m independent columns: k' <= n, or the first n already span R^n
        A = np.delete(A, bad[0], axis=1)  # later R_jj are unreliable past a dependent column
    return np.zeros((n, 0))


class GuidedES(VanillaES):
    """Vanilla-ES whose perturbations are stretched along a surrogate-gradient subspace (maximizes)."""

    def __init__(self, x0, sigma: float = 0.1, lr: float = 0.01, alpha: float = 0.5, pairs: int = 32,
                 seed: int = 0, fitness_shaping: str = "rank", optimizer: str = "adam",
                 momentum: float = 0.0, weight_decay: float = 0.0,
                 adam_betas: tuple[float, float] = (0.9, 0.999), adam_eps: float = 1e-8):
        super().__init__(x0, sigma=sigma, lr=lr, pairs=pairs, seed=seed,
                         fitness_shaping=fitness_shaping, optimizer=optimizer, momentum=momentum,
                         weight_decay=weight_decay, adam_betas=adam_betas, adam_eps=adam_eps)
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"alpha must be in [0, 1], got {alpha}")
        self.alpha = float(alpha)  # isotropic share of the search variance (paper: 0.6)
        self.U = np.zeros((self.num_params, 0))  # (n, k) subspace basis for the next ask; k=0: none

    @property
    def subspace_dim(self) -> int:
        """k, the effective rank of the current surrogate subspace (0: none)."""
        return int(self.U.shape[1])

    def guide(self, G) -> None:
        """Set the surrogate subspace used by the next ``ask``: rows of ``G`` (k, n) or one (n,) vector."""
        if self._z is not None:
            raise RuntimeError("guide() called between ask() and tell(); it shapes the next generation")
        G = np.asarray(G, dtype=np.float64)
        if G.ndim == 1:
            G = G[None, :]  # (1, n)
        if G.ndim != 2 or G.shape[1] != self.num_params:
            raise ValueError(f"surrogate must have shape (k, {self.num_params}), got {G.shape}")
        if not np.isfinite(G).all():
            raise ValueError("surrogate gradients must be finite")
        self.U = orthonormal_basis(G)  # (n, k)

    def tell(self, fitness, surrogate=None) -> None:
        """Update the mean (maximize); then ``guide(surrogate)``, or clear the subspace if None."""
        super().tell(fitness)
        self.U = np.zeros((self.num_params, 0))
        if surrogate is not None:
            self.guide(surrogate)

    def _sample_directions(self, rng: np.random.Generator) -> np.ndarray:
        z_n = super()._sample_directions(rng)  # (P, n) exactly Vanilla-ES's draw
        k = self.subspace_dim
        if k == 0 or self.alpha == 1.0:
            return z_n
        z_k = rng.standard_normal((self.pairs, k))  # (P, k)
        scale = np.sqrt((1.0 - self.alpha) * self.num_params / k)
        return np.sqrt(self.alpha) * z_n + scale * (z_k @ self.U.T)  # (P, n)  Eq. (5), times n

    def state_dict(self) -> dict[str, np.ndarray]:
        return super().state_dict() | {"U": self.U.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        U = np.array(state["U"], dtype=np.float64)
        if U.ndim != 2 or U.shape[0] != self.num_params or U.shape[1] > self.num_params:
            raise ValueError(f"U has shape {U.shape}, expected ({self.num_params}, k <= n)")
        super().load_state_dict(state)
        self.U = U
