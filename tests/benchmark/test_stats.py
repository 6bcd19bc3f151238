"""Exact values of the across-seed statistics (t quantiles, intervals, step-held bands)."""

import math

import numpy as np
import pytest

from shaped_es.report.stats import band, betainc, common_grid, step_hold, student_t_ppf, t_interval


@pytest.mark.parametrize("df, q, expected", [
    (1, 0.975, 12.706204736174698),  # tables: t_{0.975, 1}
    (2, 0.975, 4.302652729749464),
    (4, 0.975, 2.7764451051977934),
    (30, 0.975, 2.0422724563012373),
    (10, 0.995, 3.169272672616872),
    (1e7, 0.975, 1.959964221767205),  # ~ the normal quantile 1.95996398
])
def test_student_t_quantiles(df, q, expected):
    assert student_t_ppf(q, df) == pytest.approx(expected, rel=1e-9)
    assert student_t_ppf(1 - q, df) == pytest.approx(-expected, rel=1e-9)


def test_betainc_identities():
    assert betainc(1.0, 1.0, 0.3) == pytest.approx(0.3, abs=1e-14)  # uniform CDF
    assert betainc(2.0, 1.0, 0.5) == pytest.approx(0.25, abs=1e-14)  # x^a for b = 1
    a, b, x = 2.5, 0.5, 0.7
    assert betainc(a, b, x) == pytest.approx(1 - betainc(b, a, 1 - x), abs=1e-13)


def test_t_interval():
    mean, half = t_interval([1.0, 2.0, 4.0, 7.0])
    sd = np.std([1.0, 2.0, 4.0, 7.0], ddof=1)
    assert mean == 3.5
    assert half == pytest.approx(3.182446305284263 * sd / 2, rel=1e-9)
    assert t_interval([5.0, np.nan]) == (5.0, pytest.approx(math.nan, nan_ok=True))
    m, h = t_interval([])
    assert math.isnan(m) and math.isnan(h)


def test_step_hold_and_band():
    x = np.array([1.0, 2.0, 3.0, 4.0])
    y = np.array([10.0, np.nan, 30.0, np.nan])  # evaluated at x = 1 and 3 only
    grid = np.array([0.5, 1.0, 2.5, 3.0, 4.0, 5.0])
    held = step_hold(x, y, grid)
    np.testing.assert_array_equal(held, [np.nan, 10.0, 10.0, 30.0, 30.0, np.nan])
    np.testing.assert_array_equal(step_hold(x, y, grid, hold_end=True), [np.nan, 10, 10, 30, 30, 30])

    curves = [(x, np.array([0.0, 2.0, 4.0, 6.0])), (x, np.array([2.0, 4.0, 6.0, 8.0]))]
    mean, lo, hi, n = band(curves, np.array([1.0, 2.0]))
    np.testing.assert_allclose(mean, [1.0, 3.0])
    half = 12.706204736174698 * np.sqrt(2.0) / np.sqrt(2)  # t_{.975,1} * sd / sqrt(n)
    np.testing.assert_allclose(hi - mean, [half, half], rtol=1e-9)
    np.testing.assert_allclose(mean - lo, [half, half], rtol=1e-9)
    np.testing.assert_array_equal(n, [2, 2])


def test_common_grid_covers_the_shortest_run():
    xs = [np.array([1.0, 2.0, 5.0]), np.array([0.5, 3.0])]
    g = common_grid(xs, points=5)
    assert g[0] == 0.5 and g[-1] == 3.0 and g.size == 5
    np.testing.assert_array_equal(common_grid(xs, integer=True), [0.5, 1.0, 2.0, 3.0])
    g = common_grid(xs, points=3, longest=True, log=True)
    np.testing.assert_allclose(g, [0.5, np.sqrt(2.5), 5.0])
