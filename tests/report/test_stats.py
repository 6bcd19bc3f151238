"""Exact values of the across-seed statistics (t quantiles, intervals, step-held bands) and of the robust
aggregates (IQM, bootstrap intervals, probability of improvement, performance profiles)."""

import math

import numpy as np
import pytest

from shaped_es.report.aggregate import (bootstrap_ci, iqm, iqm_with_ci, performance_profile,
                                        probability_of_improvement, profile_band)
from shaped_es.report.figures import plot_performance_profile
from shaped_es.report.stats import band, common_grid, step_hold, student_t_ppf, t_interval


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


def test_iqm_of_known_arrays():
    assert iqm(np.arange(1.0, 9.0)) == 4.5  # middle half of 1..8: mean(3, 4, 5, 6)
    assert iqm([100.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, -50.0]) == 3.5  # outliers cut: mean(2, 3, 4, 5)
    assert iqm(np.arange(10.0)) == 4.5  # n = 10: 2 cut at each end (as rliable), mean(2..7)
    assert iqm([7.0]) == 7.0
    assert math.isnan(iqm([]))


def test_bootstrap_ci_contains_the_point_estimate():
    rng = np.random.default_rng(3)
    for n in (3, 10, 40):
        v = rng.normal(50.0, 20.0, n)
        est = iqm_with_ci(v)
        lo, hi = est["ci"]
        assert lo <= est["iqm"] <= hi and lo < hi
        assert v.min() <= lo and hi <= v.max()  # resamples of v: the IQM never leaves v's range
    assert bootstrap_ci([[2.0, 2.0, 2.0]], iqm) == (2.0, 2.0)  # no spread, no width
    assert bootstrap_ci([[2.0]], iqm) is None  # one seed: no interval
    assert iqm_with_ci([2.0]) == {"iqm": 2.0, "ci": None}
    # more seeds, a narrower interval
    wide, narrow = (np.diff(bootstrap_ci([rng.normal(0, 1, n)], np.mean)) for n in (5, 500))
    assert narrow < wide


def test_probability_of_improvement():
    hi, lo = np.arange(10.0) + 100.0, np.arange(10.0)
    win = probability_of_improvement(hi, lo)
    assert win["p"] == 1.0 and win["ci"] == [1.0, 1.0]
    assert win["p_value"] == pytest.approx(2 / math.comb(20, 10))  # exact two-sided: 2 of C(20, 10) orders
    assert probability_of_improvement(lo, hi)["p"] == 0.0
    same = probability_of_improvement(lo, lo)
    assert same["p"] == 0.5 and same["p_value"] == pytest.approx(1.0)
    assert same["ci"][0] < 0.5 < same["ci"][1]  # the interval of no difference straddles 0.5
    ties = probability_of_improvement([1.0, 1.0], [1.0, 1.0, 1.0])
    assert ties["p"] == 0.5 and ties["ci"] == [0.5, 0.5]
    # one overlap: x = (1, 3), y = (2,): pairs 1 < 2, 3 > 2 -> 1/2; x = (2, 3) vs (1, 2): 3.5 / 4
    assert probability_of_improvement([2.0, 3.0], [1.0, 2.0])["p"] == 0.875
    p = probability_of_improvement([2.0, 3.0, 5.0], [1.0, 4.0])
    assert p["p"] == pytest.approx(4 / 6) and p["ci"][0] <= p["p"] <= p["ci"][1]


def test_performance_profile_and_band():
    v = [1.0, 2.0, 3.0, 4.0]
    np.testing.assert_array_equal(performance_profile(v, [0.0, 1.0, 2.5, 4.0]), [1.0, 0.75, 0.5, 0.0])
    prof, lo, hi = profile_band(v, [0.0, 2.5, 5.0])
    np.testing.assert_array_equal(prof, [1.0, 0.5, 0.0])
    assert (lo <= prof).all() and (prof <= hi).all()
    assert lo[0] == hi[0] == 1.0 and lo[2] == hi[2] == 0.0  # every resample is above 0 and below 5
    assert lo[1] < 0.5 < hi[1]
    prof, lo, hi = profile_band([3.0], [2.0, 4.0])
    np.testing.assert_array_equal(np.stack([prof, lo, hi]), [[1.0, 0.0]] * 3)


def test_profile_figure_is_written(tmp_path):
    out = plot_performance_profile({"shaped": [200.0, 210.0, -25.0], "vanilla": [190.0, -25.0, 230.0],
                                    "mystery": [5.0]}, tmp_path / "f" / "profile.png", threshold=200.0,
                                   title="CarNav-v0: final test reward profile (3 seeds per method)")
    assert out == tmp_path / "f" / "profile.png" and out.stat().st_size > 10_000


def test_ratio_of_means_and_its_interval():
    """A benchmark's "shaped / vanilla" generations to the threshold: mean over mean, bootstrap interval around it."""
    from shaped_es.report.aggregate import ratio_of_means

    x, y = np.array([4.0, 6.0, 5.0, 7.0, 3.0]), np.array([20.0, 30.0, 25.0, 26.0, 24.0])
    r = ratio_of_means(x, y)
    assert r["ratio"] == pytest.approx(0.2) and r["ci"][0] < 0.2 < r["ci"][1] < 1.0
    assert ratio_of_means(x[:1], y)["ci"] is None  # one seed: no interval
    assert np.isnan(ratio_of_means(x, np.zeros(3))["ratio"])  # nothing to divide by
