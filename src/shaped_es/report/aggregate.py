"""Robust across-seed aggregates for comparing methods (Agarwal et al., "Deep RL at the Edge of the
Statistical Precipice", NeurIPS 2021), on one score per seed (the final test reward):

- ``iqm``: interquartile mean, the mean of the middle 50% of the scores (``scipy.stats.trim_mean``
  with 25% cut at each end, as rliable; for n not divisible by 4 the cut rounds down);
- ``bootstrap_ci``: percentile-bootstrap interval of any statistic. Each method's seeds are resampled
  on their own (the stratified bootstrap of rliable with the methods as strata; one env = one task);
- ``probability_of_improvement``: P(X > Y) + P(X = Y) / 2 for a random seed of X against one of Y, the
  Mann-Whitney U statistic over n_X n_Y (0.5: no difference; 1: every seed of X beats every seed of Y);
- ``performance_profile``: the fraction of seeds whose score exceeds tau, for each tau.

rliable (the paper's library) is not used: on PyPI it pulls arch, statsmodels, pandas and seaborn for
what SciPy's ``bootstrap`` and ``mannwhitneyu`` do here in a few lines.
"""

from __future__ import annotations

import math

import numpy as np


def _sps():
    """``scipy.stats``, imported on first use: it takes ~0.6 s, which a run's ``plot_runs`` figure and a
    command-line start do not need."""
    from scipy import stats

    return stats


RESAMPLES = 2000  # bootstrap resamples (rliable's default)
SEED = 0  # bootstrap seed: the same runs always give the same summary.json
EXACT_MAX = 30  # exact Mann-Whitney p-values up to this many seeds a side (SciPy's own 'auto' stops at 8)


def _finite(values) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64).ravel()
    return v[np.isfinite(v)]


def iqm(values, axis: int = -1):
    """Interquartile mean of ``values`` along ``axis`` (NaN for no values)."""
    v = np.asarray(values, dtype=np.float64)
    if v.shape[axis] == 0:
        return math.nan
    return _sps().trim_mean(v, 0.25, axis=axis)


def bootstrap_ci(samples: list, statistic, level: float = 0.95, resamples: int = RESAMPLES,
                 seed: int = SEED) -> tuple[float, float] | None:
    """Percentile-bootstrap ``level`` interval of ``statistic(*samples, axis=-1)``, each sample resampled
    with replacement on its own; None if a sample has fewer than 2 values (no interval)."""
    samples = [_finite(s) for s in samples]
    if any(s.size < 2 for s in samples):
        return None
    res = _sps().bootstrap(tuple(samples), statistic, n_resamples=resamples, confidence_level=level,
                           method="percentile", vectorized=True, paired=False, rng=np.random.default_rng(seed))
    lo, hi = res.confidence_interval
    return float(lo), float(hi)


def iqm_with_ci(values, level: float = 0.95, resamples: int = RESAMPLES) -> dict:
    """{"iqm", "ci": [lo, hi] or None} of the finite ``values``."""
    v = _finite(values)
    ci = bootstrap_ci([v], iqm, level, resamples)
    return {"iqm": float(iqm(v)) if v.size else math.nan, "ci": list(ci) if ci else None}


def _poi(x: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    """P(X > Y) + P(X = Y) / 2 over all pairs; x (..., n), y (..., m) -> (...)."""
    x, y = np.moveaxis(x, axis, -1), np.moveaxis(y, axis, -1)
    d = x[..., :, None] - y[..., None, :]  # (..., n, m)
    return ((d > 0) + 0.5 * (d == 0)).mean(axis=(-2, -1))


def probability_of_improvement(x, y, level: float = 0.95, resamples: int = RESAMPLES) -> dict:
    """P(X > Y) of a random seed of method X over one of Y, its bootstrap interval and the two-sided
    Mann-Whitney p-value (exact for up to ``EXACT_MAX`` seeds a side without ties, else the normal
    approximation with tie correction)."""
    x, y = _finite(x), _finite(y)
    if not x.size or not y.size:
        return {"p": math.nan, "ci": None, "p_value": math.nan}
    ties = np.unique(np.concatenate([x, y])).size < x.size + y.size
    exact = not ties and max(x.size, y.size) <= EXACT_MAX
    u = _sps().mannwhitneyu(x, y, alternative="two-sided", method="exact" if exact else "asymptotic")
    # u.statistic: U of x = #(x > y) + #(x = y) / 2 over all pairs
    p = float(u.statistic) / (x.size * y.size)
    ci = bootstrap_ci([x, y], _poi, level, resamples)
    return {"p": p, "ci": list(ci) if ci else None, "p_value": float(u.pvalue)}


def _ratio_of_means(x: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    """mean(x) / mean(y) along ``axis``; x (..., n), y (..., m) -> (...)."""
    return np.mean(x, axis=axis) / np.mean(y, axis=axis)


def ratio_of_means(x, y, level: float = 0.95, resamples: int = RESAMPLES) -> dict:
    """{"ratio", "ci"}: mean(X) / mean(Y) of two methods' per-seed costs (e.g. censored generations to a
    threshold) and its percentile-bootstrap interval, each method's seeds resampled on their own (None for
    fewer than 2 seeds a side); nan where Y's mean is not positive."""
    x, y = _finite(x), _finite(y)
    if not x.size or not y.size or y.mean() <= 0:
        return {"ratio": math.nan, "ci": None}
    ci = bootstrap_ci([x, y], _ratio_of_means, level, resamples) if (y > 0).all() else None
    return {"ratio": float(x.mean() / y.mean()), "ci": list(ci) if ci else None}


def performance_profile(values, taus) -> np.ndarray:
    """Fraction of the finite ``values`` strictly above each tau: (T,)."""
    v = _finite(values)
    taus = np.asarray(taus, dtype=np.float64)
    if not v.size:
        return np.full(taus.shape, np.nan)
    return (v[None, :] > taus[:, None]).mean(axis=1)  # (T,)


def profile_band(values, taus, level: float = 0.95, resamples: int = RESAMPLES):
    """``(profile, lo, hi)``, each (T,): the performance profile and its pointwise bootstrap band
    (lo = hi = profile for fewer than 2 values)."""
    taus = np.asarray(taus, dtype=np.float64)
    prof = performance_profile(values, taus)
    v = _finite(values)
    if v.size < 2:
        return prof, prof.copy(), prof.copy()

    def stat(a, axis=-1):  # a (..., n) -> (T, ...): SciPy wants the statistic's outputs first
        a = np.moveaxis(a, axis, -1)
        return (a[None, ..., :] > taus.reshape(-1, *([1] * a.ndim))).mean(axis=-1)

    res = _sps().bootstrap((v,), stat, n_resamples=resamples, confidence_level=level, method="percentile",
                           vectorized=True, rng=np.random.default_rng(SEED))
    lo, hi = (np.asarray(b, dtype=np.float64) for b in res.confidence_interval)
    return prof, lo, hi
