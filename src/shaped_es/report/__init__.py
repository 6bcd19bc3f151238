"""Figures and reports from run directories (reads ``metrics.csv``; knows nothing of training).

- ``plot_runs``: one line per run (a single run's figure after ``train``; titled method, env, seed).
- ``plot_reward_bands`` / ``plot_mphi_losses``: the paper's Fig. 4 / Fig. 5 over seeds (mean + t-interval).
- ``plot_performance_profile``: fraction of seeds above each final reward, with bootstrap bands.
- ``aggregate``: IQM, bootstrap intervals, probability of improvement; ``style``: colours per method.
"""

from shaped_es.report.figures import plot_mphi_losses, plot_performance_profile, plot_reward_bands
from shaped_es.report.plots import load_metrics, plot_runs

__all__ = ["load_metrics", "plot_mphi_losses", "plot_performance_profile", "plot_reward_bands", "plot_runs"]
