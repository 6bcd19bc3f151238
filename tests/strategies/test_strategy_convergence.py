"""Learning checks: a 10-D sphere for every strategy, and Guided ES vs Vanilla ES on the perturbed
quadratic of Maheswaranathan et al. 2019 (Guided ES, Sec. 4.1 / Fig. 1)."""

import numpy as np
import pytest

from shaped_es.strategies import GuidedES, make_strategy


def _neg_sphere(X):
    return -np.sum(X * X, axis=1)  # maximize -||x||^2


@pytest.mark.parametrize(
    "name, hyper, gens, tol",
    [
        ("vanilla", dict(sigma=0.1, lr=0.02, fitness_shaping="rank", optimizer="adam"), 400, 0.05),
        ("vanilla", dict(sigma=0.1, lr=0.1, fitness_shaping="none", optimizer="sgd"), 200, 1e-4),
        ("guided", dict(sigma=0.1, lr=0.02, alpha=0.5, optimizer="adam"), 400, 0.05),
        ("cmaes", dict(sigma=0.5, weight_decay=0.05, mu=25), 200, 1e-6),
    ],
)
def test_sphere_10d(name, hyper, gens, tol):
    x0 = np.full(10, 1.5)
    es = make_strategy(name, x0, pairs=8, seed=0, **hyper)
    for _ in range(gens):
        old = es.mean.copy()
        es.tell(_neg_sphere(es.ask()))
        if name == "guided":
            es.guide(es.mean - old)  # the trainer's PastUpdateGuide habit: last step as surrogate
    assert np.linalg.norm(es.mean) < tol, np.linalg.norm(es.mean)
    assert es.generation == gens
    assert es.best_fitness == pytest.approx(_neg_sphere(es.best_params[None])[0])


class PerturbedQuadratic:
    """f(x) = 0.5 ||A x - b||^2 / m, A (2000, 1000) and b standard normal (Guided ES paper, Sec. 4.1).

    The surrogate gradient is the true gradient plus a fixed bias and fresh noise, both scaled by the
    true gradient's norm: ``grad + ||grad|| (bias + noise)``, ``||bias|| = 1`` (fixed random direction),
    ``||noise|| = 1.5`` (redrawn every call).

    Evaluated in the eigenbasis of ``Q = A^T A / m`` (``f = 0.5 (y - y*)^T diag(lam) (y - y*) + f*``,
    ``y = V^T x``) so a loss costs O(n): every ES here draws isotropic noise, starts at 0 and gets a
    uniformly random bias direction, so the rotated problem is the same problem in distribution.
    """

    def __init__(self, m=2000, n=1000, seed=0):
        rng = np.random.default_rng(seed)
        A, b = rng.standard_normal((m, n)), rng.standard_normal(m)
        lam, V = np.linalg.eigh(A.T @ A / m)  # (n,), (n, n)
        x_star = np.linalg.solve(A.T @ A, A.T @ b)
        self.lam, self.y_star = lam, V.T @ x_star  # (n,), (n,)
        self.f_star = 0.5 * np.sum((A @ x_star - b) ** 2) / m
        bias = rng.standard_normal(n)
        self.bias = bias / np.linalg.norm(bias)
        self.n = n

    def loss(self, Y):  # (N, n) -> (N,)
        D = Y - self.y_star
        return 0.5 * (D * D) @ self.lam + self.f_star

    def surrogate(self, y, rng):
        g = self.lam * (y - self.y_star)  # true gradient (n,)
        noise = rng.standard_normal(self.n)
        noise *= 1.5 / np.linalg.norm(noise)
        return g + np.linalg.norm(g) * (self.bias + noise)


def _optimize(problem, alpha, lr, iters):
    """Excess loss f(mu) - f* after ``iters`` generations of 2 evaluations each (pairs=1, SGD)."""
    es = GuidedES(np.zeros(problem.n), sigma=0.1, lr=lr, alpha=alpha, pairs=1, seed=1,
                  fitness_shaping="none", optimizer="sgd")
    rng = np.random.default_rng(2)
    f0 = problem.loss(es.mean[None])[0]
    for _ in range(iters):
        if alpha < 1:
            es.guide(problem.surrogate(es.mean, rng))
        es.tell(-problem.loss(es.ask()))  # maximize -loss
        if not problem.loss(es.mean[None])[0] < 10 * f0:
            return np.inf  # diverged at this lr
    return problem.loss(es.mean[None])[0] - problem.f_star


def test_guided_beats_vanilla_on_perturbed_quadratic():
    problem = PerturbedQuadratic()
    start = problem.loss(np.zeros((1, problem.n)))[0] - problem.f_star
    lrs = [1.25e-4, 2.5e-4, 5e-4, 1e-3, 2e-3]  # each method at its best lr (fair); alpha = 1 is Vanilla-ES
    vanilla = min(_optimize(problem, 1.0, lr, 400) for lr in lrs)
    guided = min(_optimize(problem, 0.5, lr, 400) for lr in lrs)
    assert vanilla < start  # both make progress ...
    assert guided < 0.6 * vanilla, (start, vanilla, guided)  # ... Guided ES clearly more
