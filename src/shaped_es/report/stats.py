"""Across-seed statistics: Student-t confidence intervals and mean + CI bands of step-held curves.

    CI = mean +- t_{(1 + level) / 2, n - 1} * s / sqrt(n)          (s: sample std, ddof = 1)

The t quantile is SciPy's (``scipy.stats.t.ppf``). Robust aggregates (IQM, bootstrap intervals,
probability of improvement, performance profiles) live in ``aggregate.py``.
"""

from __future__ import annotations

import math

import numpy as np


def _sps():
    """``scipy.stats``, imported on first use: it takes ~0.6 s, which a run's ``plot_runs`` figure and a
    command-line start do not need."""
    from scipy import stats

    return stats


def student_t_ppf(q: float, df: float) -> float:
    """Quantile of Student's t with ``df`` degrees of freedom."""
    if not 0.0 < q < 1.0:
        raise ValueError(f"quantile level must lie in (0, 1), got {q}")
    return float(_sps().t.ppf(q, df))


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
    some, two = n > 0, n > 1
    mean[some] = np.nanmean(Y[:, some], axis=0)
    if two.any():
        sd = np.nanstd(Y[:, two], axis=0, ddof=1)  # (G2,)
        half[two] = _sps().t.ppf(0.5 + level / 2.0, n[two] - 1) * sd / np.sqrt(n[two])
    return mean, mean - half, mean + half, n


def common_grid(xs: list[np.ndarray], points: int = 200, integer: bool = False, longest: bool = False,
                log: bool = False, every: bool = False) -> np.ndarray:
    """Grid from the first point of any curve (``every``: from the point where every curve has begun) to
    the end of the shortest (``longest``: of the longest); ``log`` spaces it geometrically (a log axis)
    when it starts above 0."""
    xs = [x[np.isfinite(x)] for x in xs]
    xs = [x for x in xs if x.size]
    if not xs:
        return np.zeros(0)
    ends, starts = [x.max() for x in xs], [x.min() for x in xs]
    lo, hi = (max(starts) if every else min(starts)), (max(ends) if longest else min(ends))
    if integer:
        return np.unique(np.concatenate([x[(x >= lo) & (x <= hi)] for x in xs]))
    if hi <= lo:
        return np.array([hi])
    return np.geomspace(lo, hi, points) if log and lo > 0 else np.linspace(lo, hi, points)
