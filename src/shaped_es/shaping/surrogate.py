"""Surrogate gradients from behaviour-cloned parameters, and the orthonormal basis that shapes Guided ES.

Paper (Lekkala & Itti, Sec. III, "Policy shaping using surrogate gradients"): after the ES mean update
``mu_{g+1}``, every worker's cloned parameters ``theta*_i`` give one surrogate gradient

    Delta_g = (Theta*_g - mu_{g+1}) / eta                                   (Eq. Delta_g, eta = 0.01)

and ``U`` = QRDecompose(Delta_g) (Algorithm 1) is an orthonormal basis of their span, used in the Guided-ES
covariance ``Sigma = alpha/n I + (1 - alpha)/k U U^T`` (Maheswaranathan et al. 2019).

``U`` is invariant to the scale of ``eta`` (and of each row of ``Delta``): the span does not change, so
``eta`` only matters where the *magnitudes* of ``Delta`` are used (e.g. a metric or a step along Delta).

All functions are pure NumPy and compute in float64.
"""

from __future__ import annotations

import numpy as np


def surrogate_gradients(theta_star: np.ndarray, mean: np.ndarray, eta: float) -> np.ndarray:
    """``Delta = (Theta* - mu_{g+1}) / eta``: ``theta_star (k, n)``, ``mean (n,)`` -> ``(k, n)`` float64."""
    if eta <= 0:
        raise ValueError(f"eta must be positive, got {eta}")
    ts = np.atleast_2d(np.asarray(theta_star, dtype=np.float64))  # (k, n)
    mu = np.asarray(mean, dtype=np.float64).reshape(-1)  # (n,)
    if ts.shape[1] != mu.shape[0]:
        raise ValueError(f"theta_star has {ts.shape[1]} parameters, mean has {mu.shape[0]}")
    return (ts - mu[None, :]) / eta  # Eq. Delta_g: (k, n)


def clone_steps_orthogonal(theta_star: np.ndarray, theta: np.ndarray, mean: np.ndarray) -> np.ndarray:
    """The cloning steps ``theta*_i - theta_i`` with their component in the span of the generation's
    perturbations ``theta_i - mu_g`` removed: ``(k, n)`` float64 (the ``clone_orth`` surrogate).

    The paper's Delta = (theta_i + c_i - mu_{g+1}) / eta spans the perturbations themselves (so the ES
    update lies in it by construction); this keeps only what the labels add to them.
    """
    ts = np.atleast_2d(np.asarray(theta_star, dtype=np.float64))  # (k, n)
    th = np.atleast_2d(np.asarray(theta, dtype=np.float64))  # (k, n)
    eps = th - np.asarray(mean, dtype=np.float64).reshape(1, -1)  # (k, n) perturbations
    q = orthonormal_basis(eps)  # (n, k') basis of span(eps)
    c = ts - th  # (k, n) cloning steps
    return c - (c @ q) @ q.T  # (k, n)


def orthonormal_basis(delta: np.ndarray, rtol: float = 1e-6) -> np.ndarray:
    """Orthonormal basis ``U`` ``(n, k')`` of the span of the rows of ``delta`` ``(k, n)``, ``k' <= k``.

    Reduced QR of ``Delta^T`` (Algorithm 1, QRDecompose). A row whose QR residual ``|R_jj|`` is at most
    ``rtol`` times its own norm lies (numerically) in the span of the rows before it; such rows (and zero
    rows) are dropped and the QR redone, so every column of ``U`` is a real direction of the data and
    ``span(U) = span(Delta)``. Returns ``(n, 0)`` when every row is zero.
    """
    d = np.atleast_2d(np.asarray(delta, dtype=np.float64))  # (k, n)
    n = d.shape[1]
    if not np.all(np.isfinite(d)):
        raise ValueError("surrogate gradients contain NaN or inf")
    norms = np.linalg.norm(d, axis=1)  # (k,)
    d = d[norms > 0]  # (k0, n)
    norms = norms[norms > 0]
    if d.shape[0] == 0:
        return np.zeros((n, 0))
    q, r = np.linalg.qr(d.T, mode="reduced")  # (n, k0), (k0, k0)
    keep = np.abs(np.diag(r)) > rtol * norms  # (k0,) independent of the rows before
    if not keep.all():
        q, _ = np.linalg.qr(d[keep].T, mode="reduced")  # (n, k')
    return q


def cosine(a: np.ndarray, b: np.ndarray) -> float:
    """Cosine similarity of two vectors (0.0 if either is zero)."""
    a = np.asarray(a, dtype=np.float64).reshape(-1)
    b = np.asarray(b, dtype=np.float64).reshape(-1)
    na, nb = np.linalg.norm(a), np.linalg.norm(b)
    if na == 0 or nb == 0:
        return 0.0
    return float(a @ b / (na * nb))
