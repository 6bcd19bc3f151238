"""Surrogate gradients Delta = (Theta* - mu) / eta, their orthonormal basis U, and alignment metrics."""

from __future__ import annotations

import numpy as np
import pytest

from shaped_es.shaping.surrogate import cosine, orthonormal_basis, surrogate_gradients


def test_surrogate_gradients_exact_values():
    ts = np.array([[1.0, 2.0, 3.0], [0.5, 0.5, 0.5]], np.float32)  # (k, n)
    mu = np.array([1.0, 1.0, 1.0])
    d = surrogate_gradients(ts, mu, eta=0.5)
    assert d.shape == (2, 3) and d.dtype == np.float64
    np.testing.assert_array_equal(d, [[0.0, 2.0, 4.0], [-1.0, -1.0, -1.0]])
    with pytest.raises(ValueError):
        surrogate_gradients(ts, mu[:2], eta=0.01)
    with pytest.raises(ValueError):
        surrogate_gradients(ts, mu, eta=0.0)


def test_basis_is_orthonormal_and_spans_delta():
    rng = np.random.default_rng(0)
    ts = rng.normal(size=(8, 300)).astype(np.float32)
    mu = rng.normal(size=300)
    delta = surrogate_gradients(ts, mu, eta=0.01)
    U = orthonormal_basis(delta)
    assert U.shape == (300, 8)
    np.testing.assert_allclose(U.T @ U, np.eye(8), atol=1e-10)
    np.testing.assert_allclose(U @ (U.T @ delta.T), delta.T, rtol=0, atol=1e-9 * np.abs(delta).max())


def test_dependent_and_zero_rows_are_dropped():
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=50), rng.normal(size=50)
    delta = np.stack([a, b, a + b, np.zeros(50), 2 * a, 3 * b - a])  # rank 2
    U = orthonormal_basis(delta)
    assert U.shape == (50, 2)
    np.testing.assert_allclose(U.T @ U, np.eye(2), atol=1e-10)
    np.testing.assert_allclose(U @ (U.T @ delta.T), delta.T, atol=1e-10)
    delta2 = np.stack([a, a, b])  # a dependent row *before* an independent one
    U2 = orthonormal_basis(delta2)
    assert U2.shape == (50, 2)
    np.testing.assert_allclose(U2 @ (U2.T @ b), b, atol=1e-10)
    assert orthonormal_basis(np.zeros((3, 50))).shape == (50, 0)


def test_basis_span_is_invariant_to_eta():
    rng = np.random.default_rng(2)
    ts, mu = rng.normal(size=(4, 40)), rng.normal(size=40)
    U1 = orthonormal_basis(surrogate_gradients(ts, mu, eta=0.01))
    U2 = orthonormal_basis(surrogate_gradients(ts, mu, eta=3.0))
    np.testing.assert_allclose(U1 @ U1.T, U2 @ U2.T, atol=1e-10)  # same projector, same span


def test_cosine_exact_values():
    assert cosine([1.0, 0.0], [1.0, 1.0]) == pytest.approx(1 / np.sqrt(2))
    assert cosine([1.0, 2.0], [-2.0, -4.0]) == pytest.approx(-1.0)
    assert cosine([0.0, 0.0], [1.0, 1.0]) == 0.0


def test_clone_orth_removes_the_perturbation_span():
    from shaped_es.shaping.surrogate import clone_steps_orthogonal

    rng = np.random.default_rng(3)
    n, k = 50, 6
    mean = rng.normal(size=n)
    eps = rng.normal(size=(k, n))
    theta = mean + eps
    extra = rng.normal(size=n)  # a direction the labels add
    theta_star = theta + 0.3 * eps[0] + 0.1 * extra[None, :]  # part in span(eps), part outside
    G = clone_steps_orthogonal(theta_star, theta, mean)
    assert G.shape == (k, n)
    np.testing.assert_allclose(G @ eps.T, 0.0, atol=1e-9)  # nothing left in span(eps)
    q, _ = np.linalg.qr(eps.T)
    outside = 0.1 * (extra - q @ (q.T @ extra))
    np.testing.assert_allclose(G, np.tile(outside, (k, 1)), atol=1e-9)
