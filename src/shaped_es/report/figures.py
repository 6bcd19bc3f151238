"""Across-seed figures: the paper's Fig. 4 and Fig. 5 and a performance profile, one colour per method
(``style.METHOD_COLORS``, the same in every figure).

- Fig. 4: test reward (the tested policy's mean over the test episodes, ``rollout.test_policy``: the
  search's mean or its best member; PPO: its deterministic policy) vs
  generation, vs env steps (the unit of the headline claims), vs CPU time, vs wall time. Each seed's
  curve is held constant between evaluations (a step function on a common grid); the line is the mean
  across seeds and the band its t-interval, drawn only where every seed has data (from the last seed's
  first evaluation; on the cost axes a seed that finished sooner keeps its final reward to the end).
- Fig. 5: the inverse-dynamics model's train loss (``mphi_train_loss``), the paper's test loss (labels vs
  a fully trained policy's actions, ``mphi_fig5_test_loss``, logged when ``shaping.reference_run`` is
  set) and the held-out fit on the next generation's own transitions (``mphi_fit_test_loss``; older
  runs: ``mphi_test_loss``) vs its cumulative training iterations (``mphi_iterations``; else vs generation), for the runs that
  log them.
- Performance profile: the fraction of seeds whose final test reward exceeds tau, vs tau, with a
  pointwise bootstrap band (``aggregate.profile_band``).
"""

from __future__ import annotations

import io
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from shaped_es.report.aggregate import profile_band  # noqa: E402
from shaped_es.report.stats import band, common_grid  # noqa: E402
from shaped_es.report.style import method_colors  # noqa: E402
from shaped_es.rundir.atomic import atomic_write_bytes  # noqa: E402

Metrics = dict[str, np.ndarray]
X_AXES = (("generation", "generation"), ("env_steps", "env steps"), ("cpu_time_s", "CPU time (s)"),
          ("wall_time_s", "wall time (s)"))
MPHI_LOSSES = (("mphi_train_loss", "train loss"), ("mphi_fig5_test_loss", "test loss (paper: labels vs trained policy)"),
               ("mphi_fit_test_loss", "held-out fit"), ("mphi_test_loss", "held-out fit"))
INTEGER_X = ("generation", "mphi_iterations")
LOG_TIME_RATIO = 20.0


def _x(m: Metrics, key: str) -> np.ndarray:
    return m[key] + 1 if key == "generation" else m[key]  # generations completed, as plot_runs


def _has(m: Metrics, key: str) -> bool:
    return key in m and bool(np.isfinite(m[key]).any())


def _draw(ax, runs: list[Metrics], xkey: str, ykey: str, color: str, label: str, level: float,
          steps: bool = True, hold_end: bool = False, log: bool = False, ls: str = "-") -> bool:
    """Mean and band across seeds, drawn only where every seed has data: each seed's curve is held
    constant between its points on a common grid that starts where the last seed begins (a mean over the
    seeds reported so far would jump as each seed enters); ``hold_end``: a run that finished early keeps
    its final value up to the longest run's end (time axes: seeds of one method take different times)."""
    curves = [(_x(m, xkey), m[ykey]) for m in runs if _has(m, ykey) and xkey in m]
    grid = common_grid([c[0] for c in curves], points=400, integer=xkey in INTEGER_X, longest=hold_end,
                       log=log, every=True)
    if not curves or grid.size == 0:
        return False
    mean, lo, hi, n = band(curves, grid, level, hold_end=hold_end)
    partial = n < len(curves)  # (G,) a seed without a point yet (or no longer): no mean there
    mean[partial], lo[partial], hi[partial] = np.nan, np.nan, np.nan
    style = {"drawstyle": "steps-post"} if steps and xkey == "generation" else {}  # held between tests
    ax.plot(grid, mean, color=color, label=label, ls=ls, **style)
    ax.fill_between(grid, lo, hi, color=color, alpha=0.2, linewidth=0, step="post" if style else None)
    return True


def _save(fig, out: str | Path) -> Path:
    fig.tight_layout()
    return save_figure(fig, out)


def save_figure(fig, out: str | Path) -> Path:
    """``fig`` written to ``out`` (its format from the suffix) through a temporary of its own and a rename, as
    every file of a run is: a kill while drawing leaves the old figure, not an empty file; closed."""
    out = Path(out)
    buf = io.BytesIO()
    try:
        fig.savefig(buf, dpi=110, format=out.suffix.lstrip(".") or "png")
    finally:
        plt.close(fig)
    atomic_write_bytes(out, buf.getvalue())
    return out


def plot_reward_bands(groups: dict[str, list[Metrics]], out: str | Path, title: str = "",
                      level: float = 0.95) -> Path:
    """Fig. 4: four panels (generation, env steps, CPU time, wall time), mean test reward across seeds
    with a ``level`` t-interval band per method.

    The y range is the range of the seeds' own test rewards (a few-seed t-interval can reach far past
    any value observed; it is clipped there). A cost axis (env steps, times) turns logarithmic when the
    methods' totals differ by more than ``LOG_TIME_RATIO`` (ES runs of seconds next to PPO runs of
    minutes); on those axes a seed that finished sooner keeps its final reward to the longest seed's end.
    """
    fig, axes = plt.subplots(2, 2, figsize=(12, 8.4), sharey=True)
    axes = axes.ravel()
    runs = [m for rs in groups.values() for m in rs if _has(m, "test_reward_mean")]
    log = {}
    for key, _ in X_AXES[1:]:
        ends = [np.nanmax(m[key]) for m in runs if key in m and np.isfinite(m[key]).any()]
        log[key] = bool(ends and min(ends) > 0 and max(ends) / min(ends) > LOG_TIME_RATIO)
    colors = method_colors(groups)
    for method, rs in groups.items():
        for ax, (key, xlabel) in zip(axes, X_AXES):
            cost = key != "generation"
            _draw(ax, rs, key, "test_reward_mean", colors[method], f"{method} (seeds: {len(rs)})", level,
                  hold_end=cost, log=log.get(key, False))
    for ax, (key, xlabel) in zip(axes, X_AXES):
        ax.set_xlabel(xlabel)
        ax.grid(alpha=0.3)
        if log.get(key):
            ax.set_xscale("log")
        ax.tick_params(labelleft=True)
    if runs:
        ys = np.concatenate([m["test_reward_mean"][np.isfinite(m["test_reward_mean"])] for m in runs])
        pad = 0.05 * max(ys.max() - ys.min(), 1e-6 * max(1.0, abs(ys.max())))
        axes[0].set_ylim(ys.min() - pad, ys.max() + pad)
    for ax in axes[::2]:
        ax.set_ylabel(f"test reward (mean, {level:.0%} CI over seeds)")
    if axes[0].get_legend_handles_labels()[0]:
        axes[0].legend(fontsize=8, framealpha=0.9)
    fig.suptitle(title or "test reward vs generation, env steps, CPU time, wall time")
    return _save(fig, out)


def plot_performance_profile(finals: dict[str, list[float]], out: str | Path, title: str = "",
                             level: float = 0.95, threshold: float | None = None,
                             points: int = 200) -> Path:
    """Fraction of seeds with final test reward > tau vs tau, per method, with a pointwise ``level``
    bootstrap band; a dashed line marks ``threshold`` (the success threshold) when given."""
    fig, ax = plt.subplots(figsize=(7, 4.4))
    values = np.concatenate([np.asarray(v, dtype=np.float64) for v in finals.values()] or [np.zeros(0)])
    values = values[np.isfinite(values)]
    if threshold is not None and np.isfinite(threshold):
        values = np.append(values, threshold)
    if values.size:
        lo, hi = values.min(), values.max()
        pad = 0.05 * max(hi - lo, 1e-6 * max(1.0, abs(hi)))
        taus = np.linspace(lo - pad, hi + pad, points)  # (T,)
        colors = method_colors(finals)
        for method, v in finals.items():
            n = int(np.isfinite(np.asarray(v, dtype=np.float64)).sum())
            if not n:
                continue
            prof, blo, bhi = profile_band(v, taus, level)
            ax.plot(taus, prof, color=colors[method], label=f"{method} (seeds: {n})", drawstyle="steps-post")
            ax.fill_between(taus, blo, bhi, color=colors[method], alpha=0.15, linewidth=0, step="post")
        if threshold is not None and np.isfinite(threshold):
            ax.axvline(threshold, color="k", ls="--", lw=1, label=f"success threshold {threshold:g}")
        ax.legend(fontsize=8, framealpha=0.9)
    ax.set_xlabel("final test reward tau")
    ax.set_ylabel(f"fraction of seeds with reward > tau ({level:.0%} bootstrap band)")
    ax.set_ylim(-0.02, 1.02)
    ax.grid(alpha=0.3)
    ax.set_title(title or "performance profile of the final test reward")
    return _save(fig, out)


def plot_mphi_losses(groups: dict[str, list[Metrics]], out: str | Path, title: str = "",
                     level: float = 0.95) -> Path | None:
    """Fig. 5: M_phi train/test loss vs iteration; None (no file) if no run logs these columns."""
    having = {k: [m for m in runs if any(_has(m, c) for c, _ in MPHI_LOSSES)] for k, runs in groups.items()}
    having = {k: v for k, v in having.items() if v}
    if not having:
        return None
    fig, ax = plt.subplots(figsize=(7, 4.4))
    every = [m for runs in having.values() for m in runs]
    xkey = "mphi_iterations" if all(_has(m, "mphi_iterations") for m in every) else "generation"
    colors = method_colors(groups)
    for method, runs in having.items():
        for (col, name), ls in zip(MPHI_LOSSES, ("-", "-.", "--", "--")):
            if not any(_has(m, col) for m in runs):
                continue
            label = f"{method}: {name} (seeds: {len(runs)})"
            _draw(ax, runs, xkey, col, colors[method], label, level, steps=False, ls=ls)
    values = np.concatenate([m[c][np.isfinite(m[c])] for runs in having.values() for m in runs
                             for c, _ in MPHI_LOSSES if c in m])
    if values.size and values.min() > 0:
        ax.set_yscale("log")
    ax.set_xlabel("M_phi training iteration" if xkey == "mphi_iterations" else "generation")
    ax.set_ylabel("inverse-dynamics loss")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or "M_phi train and test loss")
    return _save(fig, out)
