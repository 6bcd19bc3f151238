"""Across-seed statistics: Student-t confidence intervals and mean + CI bands of step-held curves.

The t quantile is computed here (regularized incomplete beta by Lentz's continued fraction, Numerical
Recipes 6.4, then bisection) so the package needs no SciPy:

    F_t(t; nu) = 1 - I_{nu / (nu + t^2)}(nu / 2, 1 / 2) / 2        for t >= 0
    CI = mean +- t_{(1 + level) / 2, n - 1} * s / sqrt(n)          (s: sample std, ddof = 1)
"""

from __future__ import annotations

import math

import numpy as np


def _betacf(a: float, b: float, x: float) -> float:
    """Continued fraction of the incomplete beta function (modified Lentz)."""
    tiny, eps = 1e-300, 1e-15
    qab, qap, qam = a + b, a + 1.0, a - 1.0
    c, d = 1.0, 1.0 - qab * x / qap
    d = 1.0 / (d if abs(d) > tiny else tiny)
    h = d
    for m in range(1, 500):
        m2 = 2 * m
        for num in (m * (b - m) * x / ((qam + m2) * (a + m2)), -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))):
            d = 1.0 + num * d
            d = 1.0 / (d if abs(d) > tiny else tiny)
            c = 1.0 + num / c
            c = c if abs(c) > tiny else tiny
            h *= d * c
        if abs(d * c - 1.0) < eps:
            break
    return h


def betainc(a: float, b: float, x: float) -> float:
    """Regularized incomplete beta I_x(a, b) for a, b > 0 and 0 <= x <= 1."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    ln_front = math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x)
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(ln_front) * _betacf(a, b, x) / a
    return 1.0 - math.exp(ln_front) * _betacf(b, a, 1.0 - x) / b


def student_t_cdf(t: float, df: float) -> float:
    tail = 0.5 * betainc(df / 2.0, 0.5, df / (df + t * t))
    return 1.0 - tail if t >= 0 else tail


def student_t_ppf(q: float, df: float) -> float:
    """Quantile of Student's t with ``df`` degrees of freedom (bisection on the CDF)."""
    if not 0.0 < q < 1.0:
        raise ValueError(f"quantile level must lie in (0, 1), got {q}")
    if q < 0.5:
        return -student_t_ppf(1.0 - q, df)
    lo, hi = 0.0, 1.0
    while student_t_cdf(hi, df) < q:
        lo, hi = hi, hi * 2.0
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if student_t_cdf(mid, df) < q else (lo, mid)
        if hi - lo < 1e-12 * max(1.0, hi):
            break
    return 0.5 * (lo + hi)


def t_interval(values, level: float = 0.95) -> tuple[float, float]:
    """(mean, half width) of the ``level`` t-interval of the finite ``values`` (NaN half width if n < 2)."""
    v = np.asarray(values, dtype=np.float64)
    v = v[np.isfinite(v)]
    if v.size == 0:
        return math.nan, math.nan
    if v.size == 1:
        return float(v[0]), math.nan
    half = student_t_ppf(0.5 + level / 2.0, v.size - 1) * v.std(ddof=1) / math.sqrt(v.size)
    return float(v.mean()), float(half)


def step_hold(x: np.ndarray, y: np.ndarray, grid: np.ndarray, hold_end: bool = False) -> np.ndarray:
    """Value of the curve at each grid point: the last finite ``y`` at or before it (NaN before the first
    point, and after the last ``x`` unless ``hold_end``: a finished run keeps its final value there)."""
    ok = np.isfinite(x) & np.isfinite(y)
    xs, ys = x[ok], y[ok]
    out = np.full(grid.shape, np.nan)
    if xs.size == 0:
        return out
    idx = np.searchsorted(xs, grid, side="right") - 1  # (G,) index of the last point <= grid
    inside = (idx >= 0) & (hold_end | (grid <= x[np.isfinite(x)].max()))
    out[inside] = ys[idx[inside]]
    return out


def band(curves: list[tuple[np.ndarray, np.ndarray]], grid: np.ndarray, level: float = 0.95,
         hold_end: bool = False):
    """Mean and ``level`` t-interval bounds across seeds of step-held curves on ``grid``.

    Returns ``(mean, lo, hi, n)``, each ``(G,)``; ``n`` counts the seeds defined at each grid point
    (lo = hi = mean where n < 2).
    """
    Y = np.stack([step_hold(x, y, grid, hold_end) for x, y in curves]) if curves else np.zeros((0, grid.size))  # (S, G)
    n = np.isfinite(Y).sum(axis=0)  # (G,)
    mean = np.full(grid.shape, np.nan)
    half = np.zeros(grid.shape)
    for j in np.flatnonzero(n > 0):
        m, h = t_interval(Y[:, j], level)
        mean[j], half[j] = m, (h if math.isfinite(h) else 0.0)
    return mean, mean - half, mean + half, n


def common_grid(xs: list[np.ndarray], points: int = 200, integer: bool = False, longest: bool = False,
                log: bool = False) -> np.ndarray:
    """Grid from the first point of any curve to the end of the shortest (``longest``: of the longest);
    ``log`` spaces it geometrically (a log axis) when it starts above 0."""
    xs = [x[np.isfinite(x)] for x in xs]
    xs = [x for x in xs if x.size]
    if not xs:
        return np.zeros(0)
    ends = [x.max() for x in xs]
    lo, hi = min(x.min() for x in xs), (max(ends) if longest else min(ends))
    if integer:
        return np.unique(np.concatenate([x[(x >= lo) & (x <= hi)] for x in xs]))
    if hi <= lo:
        return np.array([hi])
    return np.geomspace(lo, hi, points) if log and lo > 0 else np.linspace(lo, hi, points)
