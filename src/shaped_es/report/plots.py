"""Reward curves in the layout of the paper's Fig. 4: reward vs generation, vs CPU time, vs wall time."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from shaped_es.report.figures import save_figure  # noqa: E402
from shaped_es.report.style import method_color  # noqa: E402


def load_metrics(run_dir: str | Path) -> dict[str, np.ndarray]:
    """``metrics.csv`` as columns of floats (empty cells -> NaN), read and validated by the run store (a
    damaged file is one ``StoreError`` line; a torn last row is left out)."""
    from shaped_es.rundir.store import RunStore

    rows = RunStore(run_dir).read_metrics()
    if not rows:
        return {}
    cols = {}
    for k in rows[0]:
        vals = []
        for r in rows:
            try:
                vals.append(float(r[k]) if r[k] not in ("", None) else np.nan)
            except ValueError:
                vals.append(np.nan)
        cols[k] = np.asarray(vals)
    return cols


def run_identity(run_dir: str | Path) -> dict:
    """``method``, ``env`` and ``seed`` from the run's ``config.yaml`` (missing keys: absent)."""
    from shaped_es.config import ConfigError, read_yaml

    try:
        cfg = read_yaml(Path(run_dir) / "config.yaml")
    except ConfigError:
        return {}
    return {k: cfg[k] for k in ("method", "env", "seed") if isinstance(cfg, dict) and k in cfg}


def tested_policy(run_dir: str | Path) -> str:
    """What the run's test rewards are of, for a legend: ``mean`` or ``best member`` (its
    ``rollout.test_policy``; a config without it was written before the setting, under the best-member rule),
    ``policy`` for PPO or an unreadable config."""
    from shaped_es.config import ConfigError, read_yaml
    from shaped_es.methods import METHODS
    from shaped_es.rundir.store import SAVED_BEFORE

    try:
        cfg = read_yaml(Path(run_dir) / "config.yaml")
    except ConfigError:
        return "policy"
    method = METHODS.get(cfg.get("method", "vanilla")) if isinstance(cfg, dict) else None
    if method is None or method.strategy is None:  # PPO (its own loop), or an unknown method
        return "policy"
    rollout = cfg.get("rollout") if isinstance(cfg.get("rollout"), dict) else {}
    rule = rollout.get("test_policy", SAVED_BEFORE[("rollout", "test_policy")])  # a run from before the setting
    return "mean" if rule == "mean" else "best member"


def run_title(run_dir: str | Path, title: str = "") -> str:
    """'<method> on <env>, seed <seed>' from the run's config, after ``title`` unless ``title`` only
    repeats the env or the method."""
    ident = run_identity(run_dir)
    parts = [ident.get("method"), f"on {ident['env']}" if "env" in ident else None,
             f"seed {ident['seed']}" if "seed" in ident else None]
    own = " ".join(p for p in parts[:2] if p) + (f", {parts[2]}" if parts[2] else "")
    if not title or title in (ident.get("env"), ident.get("method")):
        return own or title
    return f"{title}: {own}" if own else title


def plot_runs(runs: dict[str, str | Path], out: str | Path, title: str = "") -> Path:
    """One figure, three panels (the paper's Fig. 4 axes); one line per labelled run.

    Solid: test reward of the tested policy (where evaluated; :func:`tested_policy`); dotted: mean training
    reward. A label that
    names a method takes its fixed colour. One run: the title names its method, env and seed.
    """
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.2), sharey=True)
    xs = [("generation", "generation"), ("cpu_time_s", "CPU time (s)"), ("wall_time_s", "wall time (s)")]
    if len(runs) == 1:
        title = run_title(next(iter(runs.values())), title)
    for i, (label, run_dir) in enumerate(runs.items()):
        m = load_metrics(run_dir)
        if not m:
            continue
        color, tested = method_color(label, i), tested_policy(run_dir)
        for ax, (key, xlabel) in zip(axes, xs):
            x = m[key] + (1 if key == "generation" else 0)
            test = m.get("test_reward_mean")
            if test is not None and np.isfinite(test).any():
                ok = np.isfinite(test)
                ax.plot(x[ok], test[ok], color=color, label=f"{label} (test, {tested})")
            ax.plot(x, m["train_reward_mean"], color=color, ls=":", alpha=0.7, label=f"{label} (train mean)")
            ax.set_xlabel(xlabel)
            ax.grid(alpha=0.3)
    axes[0].set_ylabel("cumulative reward")
    axes[0].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return save_figure(fig, out)
