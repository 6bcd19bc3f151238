"""Figures and reports from run directories (reads ``metrics.csv``; knows nothing of training)."""

from shaped_es.report.plots import load_metrics, plot_runs

__all__ = ["load_metrics", "plot_runs"]
