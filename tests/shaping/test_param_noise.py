import numpy as np
import pytest

from shaped_es.shaping import kernels
from shaped_es.shaping.param_noise import normals


def test_normals_have_a_standard_normals_moments_and_are_a_function_of_seed_and_step():
    z = normals(11, 0, 200_000)
    assert z.dtype == np.float32 and z.shape == (200_000,)
    assert abs(z.mean()) < 0.01 and abs(z.std() - 1) < 0.01
    assert 2.6 < np.mean(z ** 4) < 2.8  # Irwin-Hall of four: kurtosis 2.7 (a normal's 3, a uniform's 1.8)
    assert np.abs(z).max() <= 2 * 1.7320508 + 1e-6
    np.testing.assert_array_equal(normals(11, 3, 50), normals(11, 3, 50))
    assert not np.array_equal(normals(11, 3, 50), normals(12, 3, 50))
    assert not np.array_equal(normals(11, 3, 50), normals(11, 4, 50))
    # step k of n elements continues the counter: element j of step k is counter k n + j
    np.testing.assert_array_equal(normals(5, 2, 10), normals(5, 0, 30)[20:])
    assert abs(np.corrcoef(normals(1, 0, 10_000), normals(2, 0, 10_000))[0, 1]) < 0.05


@pytest.mark.parametrize("seed", [0, 123456789, 2**64 - 1])
def test_the_kernel_draws_the_same_numbers(seed):
    want = normals(seed, 4, 64)
    got = np.array([kernels._normal(np.uint64(seed), np.uint64(4 * 64 + j)) for j in range(64)], np.float32)
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-6)


def test_a_fit_under_parameter_noise_is_the_better_fit_where_the_search_samples():
    """The point of the noise: the clone fitted at theta + s z_k minimizes the cloning loss the population
    sampled around it sees. Fitted long enough (the mean's clone is a learner kept across generations), the
    plain fit is the better one at its point and the worse one averaged over perturbations of that scale
    (measured here: 0.0004 against 0.013 at the point, 0.063 against 0.037 around it)."""
    from shaped_es.policies import MLPSpec
    from shaped_es.shaping.population_fit import FitTask, fit_rows
    from shaped_es.shaping.population_mlp import PopulationMLP

    rng = np.random.default_rng(0)
    spec, steps, B, s = MLPSpec(6, 2, (32, 32)), 4000, 64, 0.05
    rows = rng.standard_normal((128, 6)).astype(np.float32)  # (N, obs) a few states, labels a sharp function
    labels = np.tanh(3 * np.sin(4 * rows[:, :2]) * rows[:, 2:4]).astype(np.float32)  # (N, act)
    idx = rng.integers(0, len(rows), (steps, 1, B))  # (steps, 1, B)
    S, A = rows[idx], labels[idx]  # (steps, 1, B, obs), (steps, 1, B, act)
    theta = spec.init(1)[None]  # (1, n)

    def smoothed_loss(th: np.ndarray, scale: float = s) -> float:
        z = np.random.default_rng(5).standard_normal((256, th.size)).astype(np.float32)  # (256, n) the search's
        net = PopulationMLP(spec, th + scale * z)  # 256 members around th
        pred = net.forward(np.broadcast_to(rows, (256, *rows.shape)))  # (256, N, act)
        return float(((pred - labels) ** 2).mean())

    plain = fit_rows(FitTask(spec, theta, S, A, np.ones(1, bool), steps, "adam", 3e-3, 1))[0]
    noisy = fit_rows(FitTask(spec, theta, S, A, np.ones(1, bool), steps, "adam", 3e-3, 1, noise=s,
                             noise_seeds=np.array([9], np.uint64)))[0]
    assert smoothed_loss(noisy) < 0.8 * smoothed_loss(plain)
    assert smoothed_loss(plain, 0.0) < smoothed_loss(noisy, 0.0)  # the trade: a worse fit at the point itself
