"""Population layout, Guided-ES covariance and subspace, and Guided == Vanilla without a subspace."""

import numpy as np
import pytest
from helpers import run_generations, sphere

from shaped_es.strategies import CMAES, GuidedES, VanillaES, make_strategy
from shaped_es.strategies.guided import orthonormal_basis


def test_vanilla_population_is_antithetic_about_the_mean():
    mu = np.array([0.5, -1.0, 2.0, 0.0, 3.0])
    es = VanillaES(mu, sigma=0.2, pairs=4, seed=3)
    X = es.ask()
    assert X.shape == (8, 5) and es.popsize == 8 and es.num_params == 5
    np.testing.assert_allclose(X[:4] - mu, -(X[4:] - mu), rtol=0, atol=1e-15)
    np.testing.assert_allclose(X.mean(axis=0), mu, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(es.ask(), X)  # idempotent within a generation
    z = np.random.default_rng([3, 0]).standard_normal((4, 5))  # documented noise source
    np.testing.assert_array_equal(X[:4], mu + 0.2 * z)
    np.testing.assert_array_equal(X[4:], mu - 0.2 * z)


def test_vanilla_mean_update_is_eq4_with_sgd():
    mu = np.array([1.0, -2.0, 0.5])
    es = VanillaES(mu, sigma=0.1, lr=0.3, pairs=2, seed=0, optimizer="sgd", fitness_shaping="none",
                   weight_decay=0.01)
    X = es.ask()
    f = sphere(X)
    z = (X[:2] - mu) / 0.1
    expected = mu + 0.3 * ((f[:2] - f[2:]) @ z / (2 * 0.1 * 2) - 0.01 * mu)
    es.tell(f)
    np.testing.assert_allclose(es.mean, expected, rtol=1e-12)
    assert es.generation == 1
    assert es.best_fitness == f.max()
    np.testing.assert_array_equal(es.best_params, X[np.argmax(f)])


def test_guided_covariance_matches_sigma():
    n, k, alpha, sigma, P = 6, 2, 0.3, 0.5, 100_000
    G = np.random.default_rng(7).standard_normal((k, n))
    es = GuidedES(np.zeros(n), sigma=sigma, alpha=alpha, pairs=P, seed=11)
    es.guide(G)
    U = es.U
    assert U.shape == (n, k) and es.subspace_dim == k
    np.testing.assert_allclose(U.T @ U, np.eye(k), atol=1e-12)
    np.testing.assert_allclose(U @ (U.T @ G.T), G.T, atol=1e-12)  # U spans the surrogates
    eps = es.ask()[:P]  # mean 0: rows are the perturbations
    emp = eps.T @ eps / P  # (n, n)
    target = sigma**2 * (alpha * np.eye(n) + (1 - alpha) * n / k * U @ U.T)
    rel = np.linalg.norm(emp - target) / np.linalg.norm(target)
    assert rel < 0.03, rel
    assert np.trace(target) == pytest.approx(sigma**2 * n)  # same trace as Vanilla-ES


def test_guided_alpha0_samples_lie_in_the_subspace():
    n = 8
    G = np.random.default_rng(1).standard_normal((3, n))
    es = GuidedES(np.zeros(n), sigma=0.7, alpha=0.0, pairs=50, seed=2)
    es.guide(G)
    eps = es.ask()
    resid = eps - (eps @ es.U) @ es.U.T
    assert np.abs(resid).max() < 1e-10
    assert np.abs(eps).max() > 0.1


@pytest.mark.parametrize("optimizer", ["adam", "sgd"])
def test_guided_without_subspace_or_alpha1_is_vanilla_bitwise(optimizer):
    x0 = np.linspace(-1, 1, 7)
    kw = dict(sigma=0.1, lr=0.05, pairs=3, seed=5, optimizer=optimizer, momentum=0.5 * (optimizer == "sgd"),
              weight_decay=0.01)
    Xv, mv = run_generations(VanillaES(x0, **kw), 6)
    Xg, mg = run_generations(GuidedES(x0, alpha=0.5, **kw), 6)  # no surrogate
    assert np.array_equal(Xv, Xg) and np.array_equal(mv, mg)

    def sur(g, n):
        return np.random.default_rng(g).standard_normal((2, n))

    Xa, ma = run_generations(GuidedES(x0, alpha=1.0, **kw), 6, sur)  # surrogate given, alpha = 1
    assert np.array_equal(Xv, Xa) and np.array_equal(mv, ma)
    Xh, _ = run_generations(GuidedES(x0, alpha=0.5, **kw), 6, sur)  # and the subspace does change things
    assert np.array_equal(Xh[0], Xv[0]) and not np.array_equal(Xh[1], Xv[1])


def test_tell_without_surrogate_clears_and_guide_shapes_next_ask_only():
    es = GuidedES(np.zeros(4), sigma=0.1, alpha=0.2, pairs=2, seed=0)
    es.tell(sphere(es.ask()), surrogate=np.ones(4))
    assert es.subspace_dim == 1
    es.tell(sphere(es.ask()))
    assert es.subspace_dim == 0
    es.guide(np.ones((1, 4)))
    es.ask()
    with pytest.raises(RuntimeError):
        es.guide(np.ones((1, 4)))  # between ask and tell
    with pytest.raises(ValueError):
        GuidedES(np.zeros(4)).guide(np.ones((1, 5)))
    with pytest.raises(ValueError):
        GuidedES(np.zeros(4)).guide(np.array([[np.nan, 0, 0, 0]]))


def test_orthonormal_basis_rank_deficient_and_wide():
    rng = np.random.default_rng(4)
    a, b = rng.standard_normal(10), rng.standard_normal(10)
    G = np.stack([a, 2 * a, np.zeros(10), b, a - 3 * b])  # rank 2
    U = orthonormal_basis(G)
    assert U.shape == (10, 2)
    np.testing.assert_allclose(U.T @ U, np.eye(2), atol=1e-12)
    np.testing.assert_allclose(U @ (U.T @ G.T), G.T, atol=1e-12)
    # a dependent column before an independent one must not cost the independent direction
    U = orthonormal_basis(np.stack([a, a, b]))
    assert U.shape == (10, 2)
    np.testing.assert_allclose(U @ (U.T @ b), b, atol=1e-12)
    assert orthonormal_basis(np.zeros((3, 10))).shape == (10, 0)
    W = orthonormal_basis(rng.standard_normal((7, 4)))  # k >= n: the whole space
    assert W.shape == (4, 4)
    np.testing.assert_allclose(W.T @ W, np.eye(4), atol=1e-12)


def test_guided_with_k_at_least_n_is_isotropic_and_zero_surrogate_is_vanilla():
    n = 3
    es = GuidedES(np.zeros(n), sigma=1.0, alpha=0.4, pairs=50_000, seed=0)
    es.guide(np.random.default_rng(0).standard_normal((5, n)))
    assert es.subspace_dim == n
    eps = es.ask()[: es.pairs]
    np.testing.assert_allclose(eps.T @ eps / es.pairs, np.eye(n), atol=0.03)
    v = VanillaES(np.zeros(n), pairs=2, seed=9)
    g = GuidedES(np.zeros(n), pairs=2, seed=9)
    g.guide(np.zeros((2, n)))
    assert g.subspace_dim == 0 and np.array_equal(g.ask(), v.ask())


def test_make_strategy_and_bad_hyperparameters():
    x0 = np.zeros(4)
    assert isinstance(make_strategy("vanilla", x0, pairs=2), VanillaES)
    assert isinstance(make_strategy("guided", x0, alpha=0.6, pairs=2), GuidedES)
    es = make_strategy("cmaes", x0, sigma=0.2, pairs=3, mu=25, diagonal_above=2)
    assert isinstance(es, CMAES) and es.mu == 3 and es.diagonal and es.popsize == 6
    with pytest.raises(ValueError, match="unknown strategy"):
        make_strategy("pso", x0)
    for bad in [dict(sigma=0.0), dict(pairs=0), dict(optimizer="lbfgs"), dict(fitness_shaping="z"),
                dict(seed=-1), dict(lr=-1.0)]:
        with pytest.raises(ValueError):
            VanillaES(x0, **bad)
    with pytest.raises(ValueError):
        GuidedES(x0, alpha=1.5)
    with pytest.raises(ValueError):
        VanillaES(np.zeros((2, 2)))
    es = VanillaES(x0, pairs=2)
    with pytest.raises(ValueError, match="shape"):
        es.tell(np.zeros(3))
    with pytest.raises(ValueError, match="finite"):
        es.tell(np.array([0.0, np.nan, 1.0, 2.0]))


@pytest.mark.parametrize("cls", [VanillaES, GuidedES])
def test_pair_direction_replaces_the_first_pair_only(cls):
    """set_pair_direction(d): row 0 is mu + sigma sqrt(n) d/|d|, row P its mirror; every other row is
    the ask it would have been (Meier et al.'s antithetic pair along a given direction)."""
    n, P, sigma = 7, 4, 0.3
    mu = np.linspace(-1, 1, n)
    plain, paired = cls(mu, sigma=sigma, pairs=P, seed=5), cls(mu, sigma=sigma, pairs=P, seed=5)
    d = np.arange(1.0, n + 1)
    paired.set_pair_direction(3 * d)  # only the direction counts
    X, Y = plain.ask(), paired.ask()
    z1 = np.sqrt(n) * d / np.linalg.norm(d)
    np.testing.assert_allclose(Y[0], mu + sigma * z1, rtol=1e-12)
    np.testing.assert_allclose(Y[P], mu - sigma * z1, rtol=1e-12)
    rest = [i for i in range(2 * P) if i not in (0, P)]
    np.testing.assert_array_equal(Y[rest], X[rest])
    # the estimator is unchanged: the pair's return difference weighs d (sgd, no shaping, no decay)
    es = cls(mu, sigma=sigma, lr=1.0, pairs=P, seed=5, optimizer="sgd", fitness_shaping="none")
    es.set_pair_direction(d, length=2.0)
    Z = (es.ask()[:P] - mu) / sigma  # (P, n)
    np.testing.assert_allclose(Z[0], 2.0 * d / np.linalg.norm(d), rtol=1e-12)
    f = np.zeros(2 * P)
    f[0], f[P] = 1.0, -1.0  # only the pair along d differs
    es.tell(f)
    np.testing.assert_allclose(es.mean - mu, Z[0] * 2.0 / (2 * sigma * P), rtol=1e-12)
    assert es.ask() is not None and not np.allclose(es.ask()[0] - es.mean, sigma * Z[0])  # used once


def test_set_mean_moves_the_mean_and_keeps_the_optimizer_and_the_pair_survives_a_checkpoint():
    from helpers import npz_round_trip

    es = VanillaES(np.zeros(4), sigma=0.1, pairs=2, seed=1)
    es.tell(sphere(es.ask()))
    m_before = {k: v.copy() for k, v in es.opt.state_dict().items()}
    es.set_mean([1.0, 2.0, 3.0, 4.0])
    np.testing.assert_array_equal(es.mean, [1.0, 2.0, 3.0, 4.0])
    for k, v in es.opt.state_dict().items():  # Adam's moments are kept
        np.testing.assert_array_equal(v, m_before[k])
    es.set_pair_direction(np.ones(4))
    twin = VanillaES(np.zeros(4), sigma=0.1, pairs=2, seed=1)
    twin.load_state_dict(npz_round_trip(es.state_dict()))
    np.testing.assert_array_equal(twin.ask(), es.ask())  # the pending pair is part of the state
    with pytest.raises(RuntimeError, match="between ask"):
        es.set_mean(np.zeros(4))
    with pytest.raises(RuntimeError, match="between ask"):
        es.set_pair_direction(np.ones(4))
    es.tell(sphere(es.ask()))
    with pytest.raises(ValueError):
        es.set_mean([np.nan, 0, 0, 0])
    with pytest.raises(ValueError):
        es.set_pair_direction(np.ones(3))
