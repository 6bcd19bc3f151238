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

Two paths, one covariance (see :class:`VanillaES` for ``float32_above``):

- float64 (``n <= float32_above``): ``U`` = reduced Householder QR of ``G^T`` (:func:`orthonormal_basis`),
  sampled as ``z_k @ U^T``; unchanged, bit for bit.
- float32 (large policies): a Householder QR of the tall (n, k) matrix runs at level-2 BLAS speed (single
  thread, k = 64: 150 ms at n = 100k and 1.3-7 s at 1M, float32, numpy or scipy), so the basis is kept
  implicitly as ``U = B^T M`` (:func:`gram_basis`): ``B`` (k', n) the surrogates rounded to float32,
  ``M = R^{-1}`` (k', k') with ``R`` the Cholesky factor of the float64 Gram matrix ``B B^T`` (GEMM speed),
  so ``U`` is orthonormal to float64 accuracy in exact arithmetic on ``B``; the Cholesky drops a surrogate
  whose distance to the span of the earlier ones is at most :data:`RANK_RTOL_F32` (1e-5, float64 path:
  1e-6) of its norm, because the float32 sampling ``(z_k M^T) B`` resolves such a direction only to
  ~2e-8 / that share. ``U`` itself is formed only when read (``es.U``).
"""

from __future__ import annotations

import numpy as np

from shaped_es.strategies.fitness import standard_normal_f32
from shaped_es.strategies.vanilla import FLOAT32_ABOVE, VanillaES

RANK_RTOL = 1e-6  # a surrogate whose distance to the span of the previous ones is below this share
# of its own norm adds no direction and is dropped
RANK_RTOL_F32 = 1e-5  # the same on the float32 path: float32 sampling resolves a direction this close
# to the span of the others only to ~2e-8 / share (2e-3 of a sample here; measured at n = 200k)
COLUMN_BLOCK = 8192  # columns per block of the float32 path's Gram matrix and subspace product


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


def gram_basis(G: np.ndarray, rtol: float = RANK_RTOL_F32) -> tuple[np.ndarray, np.ndarray]:
    """The float32 path's basis ``U = B^T M`` of the span of the rows of ``G`` (k, n): ``(B, M)``.

    ``B`` (k', n) float32 are the kept rows of ``G`` rounded to float32 and ``M`` (k', k') float64 the
    inverse of the upper-triangular Cholesky factor ``R`` of their Gram matrix ``B B^T`` (computed in
    float64 from the float32 values, in column blocks), so ``U^T U = M^T B B^T M = I``. The Cholesky
    runs over the rows in order and skips a row whose Schur complement (its squared distance to the span
    of the kept rows before it) is at most ``(rtol * ||g_j||)^2``, as :func:`orthonormal_basis` drops a
    column with ``|R_jj| <= rtol * ||g_j||``; zero rows are dropped. Raises ``ValueError`` unless every
    value is finite and within float32's range.
    """
    G = np.asarray(G)
    if G.ndim == 1:
        G = G[None, :]  # (1, n)
    k, n = G.shape
    B = np.empty((k, n), dtype=np.float32)  # (k, n)
    W = np.zeros((k, k))  # (k, k) Gram matrix B B^T, float64
    buf = np.empty((k, min(n, COLUMN_BLOCK)))  # (k, c) float64 copy of one block of B
    with np.errstate(over="ignore", invalid="ignore"):  # non-finite values are reported below
        for s in range(0, n, COLUMN_BLOCK):
            e = min(n, s + COLUMN_BLOCK)
            blk = B[:, s:e]
            blk[...] = G[:, s:e]  # rounded to float32 (out of range -> inf)
            b = buf[:, : e - s]
            b[...] = blk  # exact
            W += b @ b.T  # (k, k) syrk
    if not np.isfinite(W).all():
        raise ValueError("surrogate gradients must be finite (and within float32 range)")
    keep, R = _greedy_cholesky(W, rtol)
    if not keep:
        return np.zeros((0, n), dtype=np.float32), np.zeros((0, 0))
    rows = B if len(keep) == k else B[keep]  # (k', n)
    return rows, np.linalg.inv(R)  # (k', n), (k', k') M = R^{-1}, upper triangular


def _greedy_cholesky(W: np.ndarray, rtol: float) -> tuple[list[int], np.ndarray]:
    """Right-looking Cholesky of the Gram matrix ``W`` (k, k) that skips (near-)dependent rows:
    ``(keep, R)`` with ``W[keep][:, keep] = R^T R``, ``R`` (k', k') upper triangular."""
    k = W.shape[0]
    norm2 = np.diag(W).copy()  # (k,) ||g_j||^2
    S = W.copy()  # (k, k) Schur complement of the kept pivots so far
    R = np.zeros((k, k))  # row j: R's row for a kept j
    keep: list[int] = []
    for j in range(k):
        d = S[j, j]  # squared distance of g_j to the span of the kept g_i, i < j
        if not d > (rtol * rtol) * norm2[j]:  # also drops zero rows (and d <= 0 from rounding)
            continue
        row = S[j, j:] / np.sqrt(d)  # (k - j,)
        R[j, j:] = row
        S[j:, j:] -= np.outer(row, row)
        keep.append(j)
    return keep, R[np.ix_(keep, keep)]


class GuidedES(VanillaES):
    """Vanilla-ES whose perturbations are stretched along a surrogate-gradient subspace.

    Maximizes fitness (``maximize=True``, default); ``maximize=False`` minimizes a loss (the subspace is
    sign-free: surrogate gradients of the loss or of the fitness span the same one). ``pairs`` or
    ``popsize`` as :class:`VanillaES`.
    """

    def __init__(self, x0, sigma: float = 0.1, lr: float = 0.01, alpha: float = 0.5,
                 pairs: int | None = None, seed: int = 0, fitness_shaping: str = "rank",
                 optimizer: str = "adam", momentum: float = 0.0, weight_decay: float = 0.0,
                 adam_betas: tuple[float, float] = (0.9, 0.999), adam_eps: float = 1e-8,
                 float32_above: int | None = FLOAT32_ABOVE, *, popsize: int | None = None,
                 maximize: bool = True):
        super().__init__(x0, sigma=sigma, lr=lr, pairs=pairs, seed=seed,
                         fitness_shaping=fitness_shaping, optimizer=optimizer, momentum=momentum,
                         weight_decay=weight_decay, adam_betas=adam_betas, adam_eps=adam_eps,
                         float32_above=float32_above, popsize=popsize, maximize=maximize)
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"alpha must be in [0, 1], got {alpha}")
        self.alpha = float(alpha)  # isotropic share of the search variance (paper: 0.6)
        self._clear_subspace()

    # -- the subspace -----------------------------------------------------------------------------
    def _clear_subspace(self) -> None:
        n = self.num_params
        self._U = np.zeros((n, 0))  # (n, k) float64 path: orthonormal basis for the next ask
        self._rows = np.zeros((0, n), dtype=np.float32)  # (k, n) float32 path: U = rows^T mix
        self._mix = np.zeros((0, 0))  # (k, k)
        self._U_cache: np.ndarray | None = None  # float32 path: U formed on first read

    @property
    def U(self) -> np.ndarray:
        """Orthonormal basis (n, k) of the surrogate subspace of the next ask (float32 on the float32
        path, formed from ``rows^T mix`` when read)."""
        if not self.float32:
            return self._U
        if self._U_cache is None:
            U = self._rows.T @ self._mix.astype(np.float32)  # (n, k)
            U.flags.writeable = False
            self._U_cache = U
        return self._U_cache

    def subspace_coordinates(self, v) -> np.ndarray:
        """``U^T v`` (k,) float64 for a vector ``v`` (n,), without forming ``U`` on the float32 path
        (``M^T (B v)``: one (k, n) pass instead of the (n, k) product ``es.U`` builds)."""
        v = np.asarray(v).reshape(-1)
        if v.shape[0] != self.num_params:
            raise ValueError(f"v must have {self.num_params} values, got {v.shape[0]}")
        if not self.float32:
            return self._U.T @ np.asarray(v, dtype=np.float64)  # (k,)
        Bv = (self._rows @ v.astype(np.float32)).astype(np.float64)  # (k,)
        return self._mix.T @ Bv  # (k,)

    @property
    def subspace_dim(self) -> int:
        """k, the effective rank of the current surrogate subspace (0: none)."""
        return int(self._rows.shape[0] if self.float32 else self._U.shape[1])

    def guide(self, G) -> None:
        """Set the surrogate subspace used by the next ``ask``: rows of ``G`` (k, n) or one (n,) vector."""
        self._between_generations("guide()")
        G = np.asarray(G)
        if G.dtype != np.float32:
            G = np.asarray(G, dtype=np.float64)
        if G.ndim == 1:
            G = G[None, :]  # (1, n)
        if G.ndim != 2 or G.shape[1] != self.num_params:
            raise ValueError(f"surrogate must have shape (k, {self.num_params}), got {G.shape}")
        if self.float32:
            rows, mix = gram_basis(G)  # checks finiteness on the Gram matrix (no extra pass)
            self._clear_subspace()
            self._rows, self._mix = rows, mix
            return
        G = np.asarray(G, dtype=np.float64)
        if not np.isfinite(G).all():
            raise ValueError("surrogate gradients must be finite")
        self._U = orthonormal_basis(G)  # (n, k)

    def tell(self, fitness, surrogate=None) -> None:
        """Update the mean (fitness to maximize, or a loss if not ``maximize``); then
        ``guide(surrogate)``, or clear the subspace if None."""
        super().tell(fitness)
        self._clear_subspace()
        if surrogate is not None:
            self.guide(surrogate)

    def _sample_directions(self, rng: np.random.Generator) -> np.ndarray:
        k = self.subspace_dim
        if k == 0 or self.alpha == 1.0:
            return super()._sample_directions(rng)  # (P, n) exactly Vanilla-ES's draw
        scale = np.sqrt((1.0 - self.alpha) * self.num_params / k)
        if not self.float32:
            z_n = super()._sample_directions(rng)  # (P, n) Vanilla-ES's draw
            z_k = rng.standard_normal((self.pairs, k))  # (P, k)
            return np.sqrt(self.alpha) * z_n + scale * (z_k @ self.U.T)  # (P, n)  Eq. (5), times n
        z = standard_normal_f32(rng, (self.pairs, self.num_params), scale=np.sqrt(self.alpha),
                                out=self._noise_buffer())  # (P, n)
        z_k = rng.standard_normal((self.pairs, k))  # (P, k)
        w = ((scale * z_k) @ self._mix.T).astype(np.float32)  # (P, k): U z_k = rows^T (mix z_k)
        tmp = np.empty((self.pairs, min(self.num_params, COLUMN_BLOCK)), dtype=np.float32)
        for s in range(0, self.num_params, COLUMN_BLOCK):  # z += w @ rows, one column block at a time
            e = min(self.num_params, s + COLUMN_BLOCK)
            t = tmp[:, : e - s]
            np.matmul(w, self._rows[:, s:e], out=t)  # (P, c)
            z[:, s:e] += t
        return z  # (P, n)  Eq. (5), times n

    # -- state --------------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        if self.float32:  # the implicit basis: U = U_rows^T U_mix
            return super().state_dict() | {"U_rows": self._rows.copy(), "U_mix": self._mix.copy()}
        return super().state_dict() | {"U": self._U.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Either basis format loads on either path (``U``; or ``U_rows`` + ``U_mix``)."""
        n = self.num_params
        if "U_rows" in state:
            rows = np.array(state["U_rows"], dtype=np.float32)
            mix = np.array(state["U_mix"], dtype=np.float64)
            k = rows.shape[0] if rows.ndim == 2 else -1
            if rows.ndim != 2 or rows.shape[1] != n or k > n or mix.shape != (k, k):
                raise ValueError(f"U_rows / U_mix have shapes {rows.shape} / {mix.shape}, expected "
                                 f"(k, {n}) / (k, k), k <= n")
            U = None
        else:
            U = np.array(state["U"], dtype=np.float64)
            if U.ndim != 2 or U.shape[0] != n or U.shape[1] > n:
                raise ValueError(f"U has shape {U.shape}, expected ({n}, k <= n)")
        super().load_state_dict(state)
        self._clear_subspace()
        if self.float32 and U is None:
            self._rows, self._mix = rows, mix
        elif self.float32:
            self._rows, self._mix = np.ascontiguousarray(U.T, dtype=np.float32), np.eye(U.shape[1])
        elif U is None:
            self._U = rows.T.astype(np.float64) @ mix  # (n, k)
        else:
            self._U = U
