"""The float32 path of Vanilla/Guided ES (large policies): the same statistics as the float64 path.

``float32_above=0`` forces the path on small problems so the covariance checks run at the float64
tests' sizes; one check runs at the default threshold on a policy-sized problem.
"""

import math

import numpy as np
import pytest
from helpers import npz_round_trip, run_generations, sphere

from shaped_es.strategies import GuidedES, VanillaES
from shaped_es.strategies.fitness import standard_normal_f32
from shaped_es.strategies.guided import RANK_RTOL_F32, gram_basis, orthonormal_basis
from shaped_es.strategies.vanilla import FLOAT32_ABOVE


def _phi(x):
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


# -- the noise ------------------------------------------------------------------------------------
def test_standard_normal_f32_is_standard_normal():
    z = standard_normal_f32(np.random.default_rng(0), (40, 100_001)).ravel().astype(np.float64)
    N = z.size
    assert abs(z.mean()) < 5 / math.sqrt(N)
    assert abs(z.var() - 1) < 5 * math.sqrt(2 / N)
    assert abs(np.mean(z**3)) < 5 * math.sqrt(15 / N)
    assert abs(np.mean(z**4) - 3) < 5 * math.sqrt(96 / N)
    for q in (-3.0, -2.0, -1.0, -0.3, 0.0, 0.5, 1.5, 2.5, 3.5):  # CDF at a few points (binomial s.e.)
        p = _phi(q)
        assert abs(np.mean(z <= q) - p) < 5 * math.sqrt(p * (1 - p) / N) + 1e-7, q
    assert 4.5 < np.abs(z).max() <= 5.77  # the 24-bit uniforms bound the tails (documented)


def test_standard_normal_f32_values_are_independent_within_and_across_blocks():
    z = standard_normal_f32(np.random.default_rng(1), (200_000,)).astype(np.float64)
    half = 1 << 15  # cos and sin halves of one block come from the same uniforms
    a, b = z[:half], z[half : 2 * half]
    assert abs(np.corrcoef(a, b)[0, 1]) < 5 / math.sqrt(half)
    assert abs(np.corrcoef(a**2, b**2)[0, 1]) < 5 / math.sqrt(half)  # r is shared: not even in squares
    assert abs(np.corrcoef(z[:-1], z[1:])[0, 1]) < 5 / math.sqrt(z.size)


def test_standard_normal_f32_shape_scale_determinism_and_out():
    a = standard_normal_f32(np.random.default_rng(3), (3, 5))
    b = standard_normal_f32(np.random.default_rng(3), (3, 5))
    assert a.dtype == np.float32 and a.shape == (3, 5) and np.array_equal(a, b)
    s = standard_normal_f32(np.random.default_rng(3), (3, 5), scale=0.5)
    np.testing.assert_allclose(s, 0.5 * a, rtol=1e-6)
    out = np.empty((3, 5), np.float32)
    assert standard_normal_f32(np.random.default_rng(3), (3, 5), out=out) is out
    assert np.array_equal(out, a)
    assert standard_normal_f32(np.random.default_rng(0), (0,)).shape == (0,)
    assert standard_normal_f32(np.random.default_rng(0), (7,)).shape == (7,)  # odd sizes
    with pytest.raises(ValueError):
        standard_normal_f32(np.random.default_rng(0), (3, 5), out=np.empty((5, 3), np.float32))


# -- Vanilla-ES -----------------------------------------------------------------------------------
def test_path_choice_by_size():
    assert not VanillaES(np.zeros(FLOAT32_ABOVE), pairs=1).float32
    assert VanillaES(np.zeros(FLOAT32_ABOVE + 1), pairs=1).float32
    assert not VanillaES(np.zeros(FLOAT32_ABOVE + 1), pairs=1, float32_above=None).float32
    assert VanillaES(np.zeros(3), pairs=1, float32_above=0).float32
    assert VanillaES(np.zeros(2400), pairs=2).ask().dtype == np.float64  # small policies: unchanged
    with pytest.raises(ValueError):
        VanillaES(np.zeros(3), float32_above=-1)


def test_vanilla_f32_population_gradient_and_best():
    mu = np.linspace(-1, 1, 50)
    es = VanillaES(mu, sigma=0.2, lr=0.3, pairs=6, seed=3, optimizer="sgd", fitness_shaping="none",
                   float32_above=0)
    X = es.ask()
    assert X.dtype == np.float32 and X.shape == (12, 50)
    np.testing.assert_array_equal(es.ask(), X)  # the same values until tell
    z = standard_normal_f32(np.random.default_rng([3, 0]), (6, 50))  # documented noise source
    mu32 = mu.astype(np.float32)
    np.testing.assert_array_equal(X[:6], mu32 + np.float32(0.2) * z)
    np.testing.assert_array_equal(X[6:], mu32 - np.float32(0.2) * z)
    f = sphere(X)
    es.tell(f)
    expected = mu + 0.3 * ((f[:6] - f[6:]) @ z.astype(np.float64) / (2 * 0.2 * 6))  # Eq. (4) in float64
    np.testing.assert_allclose(es.mean, expected, rtol=1e-6, atol=1e-7)
    assert es.mean.dtype == np.float64
    assert es.best_fitness == f.max()
    np.testing.assert_array_equal(es.best_params, X[np.argmax(f)].astype(np.float64))  # the asked row


def test_guided_f32_without_subspace_or_alpha1_is_vanilla_bitwise():
    x0 = np.linspace(-1, 1, 40)
    kw = dict(sigma=0.1, lr=0.05, pairs=3, seed=5, weight_decay=0.01, float32_above=0)
    Xv, mv = run_generations(VanillaES(x0, **kw), 5)
    Xg, mg = run_generations(GuidedES(x0, alpha=0.5, **kw), 5)
    assert np.array_equal(Xv, Xg) and np.array_equal(mv, mg)

    def sur(g, n):
        return np.random.default_rng(g).standard_normal((2, n))

    Xa, ma = run_generations(GuidedES(x0, alpha=1.0, **kw), 5, sur)
    assert np.array_equal(Xv, Xa) and np.array_equal(mv, ma)
    Xh, _ = run_generations(GuidedES(x0, alpha=0.5, **kw), 5, sur)
    assert np.array_equal(Xh[0], Xv[0]) and not np.array_equal(Xh[1], Xv[1])


def test_vanilla_f32_learns_the_sphere():
    es = VanillaES(np.full(10, 1.5), sigma=0.1, lr=0.02, pairs=8, seed=0, float32_above=0)
    for _ in range(400):
        es.tell(sphere(es.ask()))
    assert np.linalg.norm(es.mean) < 0.05


# -- Guided ES ------------------------------------------------------------------------------------
def test_guided_f32_covariance_matches_sigma():
    n, k, alpha, sigma, P = 6, 2, 0.3, 0.5, 100_000  # as test_guided_covariance_matches_sigma
    G = np.random.default_rng(7).standard_normal((k, n))
    es = GuidedES(np.zeros(n), sigma=sigma, alpha=alpha, pairs=P, seed=11, float32_above=0)
    es.guide(G)
    U = es.U.astype(np.float64)
    assert U.shape == (n, k) and es.subspace_dim == k
    np.testing.assert_allclose(U.T @ U, np.eye(k), atol=1e-6)
    np.testing.assert_allclose(U @ (U.T @ G.T), G.T, atol=1e-6)  # U spans the surrogates
    eps = es.ask()[:P].astype(np.float64)
    emp = eps.T @ eps / P
    target = sigma**2 * (alpha * np.eye(n) + (1 - alpha) * n / k * U @ U.T)
    rel = np.linalg.norm(emp - target) / np.linalg.norm(target)
    assert rel < 0.03, rel


def test_guided_f32_alpha0_samples_lie_in_the_subspace():
    n = 8
    G = np.random.default_rng(1).standard_normal((3, n))
    es = GuidedES(np.zeros(n), sigma=0.7, alpha=0.0, pairs=50, seed=2, float32_above=0)
    es.guide(G)
    eps = es.ask().astype(np.float64)
    U = es.U.astype(np.float64)
    resid = eps - (eps @ U) @ U.T
    assert np.abs(resid).max() < 1e-5 and np.abs(eps).max() > 0.1


def test_guided_f32_at_the_default_threshold_has_the_covariance_along_and_across_the_subspace():
    n, k, alpha, sigma, P = FLOAT32_ABOVE + 5_000, 4, 0.6, 0.1, 400
    es = GuidedES(np.zeros(n), sigma=sigma, alpha=alpha, pairs=P, seed=4)
    assert es.float32
    rng = np.random.default_rng(5)
    es.guide(rng.standard_normal((k, n)))
    U = es.U.astype(np.float64)  # (n, k)
    np.testing.assert_allclose(U.T @ U, np.eye(k), atol=1e-5)
    eps = es.ask()[:P].astype(np.float64)  # (P, n), mean 0
    along = eps @ U  # (P, k): variance sigma^2 (alpha + (1 - alpha) n / k)
    V = rng.standard_normal((n, 8))
    V -= U @ (U.T @ V)
    V /= np.linalg.norm(V, axis=0)  # 8 random unit directions orthogonal to U: variance sigma^2 alpha
    across = eps @ V  # (P, 8)
    # relative standard error of a variance estimated from m independent normal values: sqrt(2 / m)
    target_along = sigma**2 * (alpha + (1 - alpha) * n / k)
    assert abs(np.mean(along**2) / target_along - 1) < 5 * math.sqrt(2 / (P * k))
    assert abs(np.mean(across**2) / (sigma**2 * alpha) - 1) < 5 * math.sqrt(2 / (P * 8))
    cross = (along.T @ across) / P / math.sqrt(np.mean(along**2) * np.mean(across**2))
    assert np.abs(cross).max() < 6 / math.sqrt(P)  # no correlation between the parts


def test_gram_basis_spans_like_the_qr_and_drops_dependent_rows():
    rng = np.random.default_rng(4)
    a, b = rng.standard_normal(10), rng.standard_normal(10)
    G = np.stack([a, 2 * a, np.zeros(10), b, a - 3 * b])  # rank 2 (as the float64 test)
    rows, mix = gram_basis(G)
    assert rows.shape == (2, 10) and mix.shape == (2, 2) and rows.dtype == np.float32
    U = rows.T.astype(np.float64) @ mix
    np.testing.assert_allclose(U.T @ U, np.eye(2), atol=1e-10)  # orthonormal on the float32 rows
    np.testing.assert_allclose(U @ (U.T @ G.T), G.T, atol=1e-5)
    rows, mix = gram_basis(np.stack([a, a, b]))  # a dependent row before an independent one
    assert rows.shape == (2, 10)
    assert gram_basis(np.zeros((3, 10)))[0].shape == (0, 10)
    # a row this close to the span of the others is dropped; one a bit farther is kept
    c = rng.standard_normal(10)
    c -= np.stack([a, b]).T @ np.linalg.lstsq(np.stack([a, b]).T, c, rcond=None)[0]
    c /= np.linalg.norm(c)
    for share, kept in ((0.3 * RANK_RTOL_F32, 2), (3 * RANK_RTOL_F32, 3)):
        g = a + share * np.linalg.norm(a) * c
        assert gram_basis(np.stack([a, b, g]))[0].shape[0] == kept, share
    # the same subspace as the float64 QR on a well-conditioned problem
    G = rng.standard_normal((16, 5000))
    rows, mix = gram_basis(G)
    U = rows.T.astype(np.float64) @ mix
    Q = orthonormal_basis(G)
    np.testing.assert_allclose(np.linalg.svd(U.T @ Q, compute_uv=False), np.ones(16), atol=1e-6)  # angles 0


def test_guide_f32_rejects_nonfinite_and_keeps_the_old_subspace():
    es = GuidedES(np.zeros(20), sigma=0.1, alpha=0.5, pairs=2, seed=0, float32_above=0)
    G = np.random.default_rng(0).standard_normal((3, 20))
    es.guide(G)
    rows = es.state_dict()["U_rows"]
    for bad in (np.nan, np.inf, 1e39):  # 1e39 does not fit float32
        H = G.copy()
        H[1, 4] = bad
        with pytest.raises(ValueError, match="finite"):
            es.guide(H)
        assert np.array_equal(es.state_dict()["U_rows"], rows)
    with pytest.raises(ValueError):
        es.guide(np.ones((1, 19)))
    es.ask()
    with pytest.raises(RuntimeError):
        es.guide(G)


def test_basis_formats_load_on_either_path():
    n = 30
    G = np.random.default_rng(2).standard_normal((3, n))
    kw = dict(sigma=0.1, alpha=0.4, pairs=2, seed=1)
    f32 = GuidedES(np.zeros(n), float32_above=0, **kw)
    f64 = GuidedES(np.zeros(n), **kw)
    f32.guide(G)
    f64.guide(G)
    s32, s64 = npz_round_trip(f32.state_dict()), npz_round_trip(f64.state_dict())
    assert "U_rows" in s32 and "U_mix" in s32 and "U" not in s32 and "U" in s64
    a = GuidedES(np.zeros(n), **kw)
    a.load_state_dict(s32)  # float32 basis on the float64 path
    np.testing.assert_allclose(a.U @ a.U.T, f64.U @ f64.U.T, atol=1e-6)
    b = GuidedES(np.zeros(n), float32_above=0, **kw)
    b.load_state_dict(s64)  # float64 basis (an older checkpoint) on the float32 path
    np.testing.assert_allclose(b.U.astype(np.float64), f64.U, atol=1e-7)
    bad = dict(s32, U_mix=np.eye(2))
    with pytest.raises(ValueError):
        b.load_state_dict(bad)


def test_guided_f32_with_k_at_least_n_is_isotropic():
    n = 3
    es = GuidedES(np.zeros(n), sigma=1.0, alpha=0.4, pairs=50_000, seed=0, float32_above=0)
    es.guide(np.random.default_rng(0).standard_normal((5, n)))
    assert es.subspace_dim == n  # the two extra rows are dependent and dropped
    eps = es.ask()[: es.pairs].astype(np.float64)
    np.testing.assert_allclose(eps.T @ eps / es.pairs, np.eye(n), atol=0.03)
    es.tell(np.zeros(2 * es.pairs), surrogate=np.zeros((2, n)))
    assert es.subspace_dim == 0


@pytest.mark.parametrize("float32_above", [None, 0])
def test_subspace_coordinates_is_U_transpose_v(float32_above):
    n = 40
    es = GuidedES(np.zeros(n), pairs=2, alpha=0.5, float32_above=float32_above)
    assert es.subspace_coordinates(np.ones(n)).shape == (0,)
    rng = np.random.default_rng(8)
    es.guide(rng.standard_normal((5, n)))
    v = rng.standard_normal(n)
    expected = es.U.astype(np.float64).T @ v
    np.testing.assert_allclose(es.subspace_coordinates(v), expected, rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError):
        es.subspace_coordinates(np.ones(n + 1))
