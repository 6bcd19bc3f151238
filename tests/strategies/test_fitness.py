"""Exact values of the pure helpers in shaped_es.strategies.fitness and optim."""

import numpy as np
import pytest

from shaped_es.strategies.fitness import (
    antithetic,
    antithetic_gradient,
    centered_ranks,
    identity,
    l2_decay,
    l2_fitness_penalty,
    shape_fitness,
)
from shaped_es.strategies.optim import SGD, Adam, make_optimizer


def test_centered_ranks_distinct():
    f = np.array([3.0, -1.0, 10.0, 0.5, 7.0])
    np.testing.assert_array_equal(centered_ranks(f), [0.0, -1.0, 1.0, -0.5, 0.5])


def test_centered_ranks_two_elements():
    np.testing.assert_array_equal(centered_ranks([5.0, -2.0]), [1.0, -1.0])
    np.testing.assert_array_equal(centered_ranks([-2.0, 5.0]), [-1.0, 1.0])


def test_centered_ranks_ties_share_mean_rank():
    # sorted: 1, 2, 2, 4 -> ranks 0, 1.5, 1.5, 3 -> 2r/3 - 1
    np.testing.assert_array_equal(centered_ranks([2.0, 1.0, 4.0, 2.0]), [0.0, -1.0, 1.0, 0.0])
    np.testing.assert_array_equal(centered_ranks([7.0, 7.0]), [0.0, 0.0])
    r = 2 * 1.0 / 3 - 1  # mean rank 1 of 0..3
    np.testing.assert_array_equal(centered_ranks([1.0, 1.0, 1.0, 9.0]), [r, r, r, 1.0])


def test_centered_ranks_order_independent_and_monotone():
    rng = np.random.default_rng(0)
    f = rng.integers(0, 5, size=40).astype(float)  # many ties
    r = centered_ranks(f)
    perm = rng.permutation(40)
    np.testing.assert_array_equal(centered_ranks(f[perm]), r[perm])
    assert r.min() >= -1 and r.max() <= 1 and abs(r.sum()) < 1e-12
    order = np.argsort(f, kind="stable")
    assert np.all(np.diff(r[order]) >= 0)


def test_centered_ranks_rejects_nan_and_handles_tiny():
    with pytest.raises(ValueError):
        centered_ranks([1.0, np.nan])
    np.testing.assert_array_equal(centered_ranks([3.0]), [0.0])


def test_identity_and_shape_fitness():
    f = np.array([1, 5, 2])
    out = identity(f)
    assert out.dtype == np.float64 and out is not f
    np.testing.assert_array_equal(out, [1.0, 5.0, 2.0])
    np.testing.assert_array_equal(shape_fitness(f, "rank"), [-1.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="fitness_shaping"):
        shape_fitness(f, "zscore")


def test_antithetic_mirrors_exactly():
    z = np.random.default_rng(1).standard_normal((3, 4))
    a = antithetic(z)
    assert a.shape == (6, 4)
    np.testing.assert_array_equal(a[:3], z)
    np.testing.assert_array_equal(a[3:], -z)
    np.testing.assert_array_equal(a[:3] + a[3:], np.zeros((3, 4)))


def test_antithetic_gradient_exact():
    z = np.array([[1.0, 2.0], [0.0, -1.0]])  # P=2
    f = np.array([3.0, 1.0, 1.0, 2.0])  # F+ = [3, 1], F- = [1, 2] -> diff [2, -1]
    # 1/(2 * 0.5 * 2) * (2 * [1, 2] + (-1) * [0, -1]) = 0.5 * [2, 5]
    np.testing.assert_array_equal(antithetic_gradient(z, f, sigma=0.5), [1.0, 2.5])
    with pytest.raises(ValueError):
        antithetic_gradient(z, f[:3], sigma=0.5)


def test_antithetic_gradient_is_the_gradient_on_a_linear_function():
    # F(x) = w.x: F+ - F- = 2 sigma w.z_i, so g = (1/P) sum z_i z_i^T w -> w for many samples
    rng = np.random.default_rng(2)
    w, sigma, P = np.array([1.0, -2.0, 0.5]), 0.3, 20000
    z = rng.standard_normal((P, 3))
    X = sigma * antithetic(z)  # (2P, 3) around mu = 0
    g = antithetic_gradient(z, X @ w, sigma)
    np.testing.assert_allclose(g, w, atol=0.05)


def test_weight_decay_helpers_exact():
    np.testing.assert_array_equal(l2_decay([1.0, 1.0], [2.0, -4.0], 0.25), [0.5, 2.0])
    np.testing.assert_array_equal(l2_decay([1.0, 1.0], [2.0, -4.0], 0.0), [1.0, 1.0])
    X = np.array([[1.0, 3.0], [2.0, 0.0]])  # mean squares 5, 2
    np.testing.assert_array_equal(l2_fitness_penalty([10.0, 10.0], X, 0.5), [7.5, 9.0])


def test_sgd_momentum_exact():
    opt = SGD(2, lr=0.5, momentum=0.5)
    x = opt.step(np.zeros(2), np.array([1.0, -2.0]))  # buf = g
    np.testing.assert_array_equal(x, [0.5, -1.0])
    x = opt.step(x, np.array([1.0, 0.0]))  # buf = 0.5 * [1, -2] + [1, 0] = [1.5, -1]
    np.testing.assert_array_equal(x, [1.25, -1.5])


def test_adam_first_step_is_lr_times_sign():
    opt = Adam(3, lr=0.1, eps=0.0)
    x = opt.step(np.ones(3), np.array([2.0, -0.001, 5.0]))
    np.testing.assert_allclose(x, [1.1, 0.9, 1.1], rtol=0, atol=1e-15)
    assert opt.t == 1
    with pytest.raises(ValueError):
        make_optimizer("rmsprop", 3, 0.1)


def test_reset_momentum_forgets_the_direction_and_keeps_the_scale():
    sgd = SGD(2, lr=0.5, momentum=0.5)
    sgd.step(np.zeros(2), np.array([1.0, -2.0]))
    sgd.reset_momentum()
    np.testing.assert_array_equal(sgd.step(np.zeros(2), np.array([1.0, 0.0])), [0.5, 0.0])  # buf = g alone
    adam = Adam(2, lr=0.1, eps=0.0)
    adam.step(np.zeros(2), np.array([3.0, -3.0]))
    v, t = adam.v.copy(), adam.t
    adam.reset_momentum()
    assert np.all(adam.m == 0) and np.array_equal(adam.v, v) and adam.t == t
    # the next step along the opposite gradient: only (1 - b1) of it, bias-corrected at t = 2, over sqrt(v_hat)
    x = adam.step(np.zeros(2), np.array([-3.0, 3.0]))
    want = 0.1 * (0.1 * np.array([-3.0, 3.0]) / (1 - 0.9**2)) / np.sqrt(9.0)  # v_hat = 9 exactly
    np.testing.assert_allclose(x, want, rtol=1e-12)


def test_strategies_layer_imports_only_numpy_and_cma():
    import ast
    from pathlib import Path

    import shaped_es.strategies as pkg

    allowed = {"__future__", "numpy", "cma", "shaped_es.strategies"}
    for path in Path(pkg.__file__).parent.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                names = [node.module or ""]
            else:
                continue
            for name in names:
                assert any(name == a or name.startswith(a + ".") for a in allowed), (path.name, name)
