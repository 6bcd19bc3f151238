"""The benchmark report: figures (Fig. 4, Fig. 5), ``summary.json`` and a Markdown page beside them.

``write_report`` works on any run directories grouped by method, so ``shaped-es benchmark`` and
``shaped-es report RUN... --out report.md`` produce the same page.
"""

from __future__ import annotations

import json
import math
from dataclasses import asdict
from pathlib import Path

from shaped_es.benchmark.summary import load_runs, method_settings, summarize
from shaped_es.config import RunConfig
from shaped_es.report.figures import plot_mphi_losses, plot_reward_bands
from shaped_es.store import atomic_write_text

FIG4, FIG5 = "fig4_test_reward.png", "fig5_mphi_loss.png"


def _num(v, digits: int = 2) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    if isinstance(v, float) and digits == 0:
        return f"{v:,.0f}"
    return f"{v:.{digits}f}" if isinstance(v, float) else str(v)


def _reward(s: dict) -> str:
    mean, ci = s["final_test_reward_mean"], s["final_test_reward_ci"]
    if ci is None:
        return _num(mean)
    return f"{_num(mean)} ± {_num((ci[1] - ci[0]) / 2)}"


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *["| " + " | ".join(r) + " |" for r in rows]]


def render_markdown(summary: dict, figures: dict[str, str | None], runs: dict[str, list[str]],
                    settings: dict[str, dict], title: str) -> str:
    level, target, methods = summary["ci_level"], summary["target"], summary["methods"]
    out = [f"# {title}", ""]
    seeds = ", ".join(f"{k} {v['seeds']}" for k, v in methods.items())
    out += [f"Methods: {', '.join(methods)}; seeds per method: {seeds}. "
            f"Intervals: {level:.0%} Student-t over seeds.", ""]
    out += ["## Fig. 4: test reward vs generation, CPU time and wall time", "",
            "Mean across seeds of the test reward (ES: the generation's best member over the test episodes; "
            "PPO: the deterministic policy on the same test seeds), band: confidence interval; on the time "
            "panels a seed that finished sooner keeps its final reward up to the slowest seed's end.", "", f"![Fig. 4]({figures['fig4']})", ""]
    out += ["## Fig. 5: inverse-dynamics model loss", ""]
    if figures.get("fig5"):
        out += ["M_phi train loss and test loss vs its training iterations (mean over seeds, CI band).", "",
                f"![Fig. 5]({figures['fig5']})", ""]
    else:
        out += ["_Not drawn: no run logs `mphi_train_loss` / `mphi_test_loss` (the shaped method's "
                "columns)._", ""]
    ref = f" (reference method: {target['reference']})" if target.get("reference") else ""
    out += ["## Results per method", "",
            f"Target: the best baseline's final test reward, {_num(target['value'])} "
            f"({target['method']}){ref}. 'to target': first evaluation reaching it, mean over the seeds "
            "that did.", ""]
    header = ["method", "seeds", f"final test reward (± {level:.0%} CI)", "best test reward", "reached",
              "generations to target", "wall time to target (s)", "env steps to target", "generations",
              "env steps", "CPU time (s)", "wall time (s)"]
    rows = [[k, str(s["seeds"]), _reward(s), _num(s["best_test_reward_mean"]), s["reached_target"],
             _num(s["generations_to_target"], 1), _num(s["wall_time_to_target_s"], 1),
             _num(s["env_steps_to_target"], 0), _num(s["generations"], 0), _num(s["env_steps"], 0),
             _num(s["cpu_time_s"], 1), _num(s["wall_time_s"], 1)] for k, s in methods.items()]
    out += [*_table(header, rows), ""]
    phases = sorted({p for s in methods.values() for p in s["time_split_s"]})
    if phases:
        out += ["## Time per phase", "", "Seconds per run summed over generations, mean over seeds "
                "(`gen_time_s`: whole generations; the others are phases within them, and phases that run "
                "concurrently, such as M_phi training during the rollouts, overlap).", ""]
        out += [*_table(["method", *phases], [[k, *[_num(s["time_split_s"].get(p), 1) for p in phases]]
                                              for k, s in methods.items()]), ""]
    out += ["## Settings", "", *_table(["method", *next(iter(settings.values()), {}).keys()],
                                       [[k, *[f"`{json.dumps(v)}`" for v in st.values()]]
                                        for k, st in settings.items()]), ""]
    if summary.get("ppo_settings"):
        ppo = ", ".join(f"{k} {v}" for k, v in summary["ppo_settings"].items())
        out += [f"PPO (Stable-Baselines3, one torch thread): {ppo}; a generation = the whole number of PPO "
                "iterations nearest to one ES generation's largest env-step budget (`gen_env_steps`).", ""]
    out += ["## Runs", ""] + [f"- {k}: " + ", ".join(f"`{r}`" for r in rs) for k, rs in runs.items()] + [""]
    return "\n".join(out)


def write_report(out_md: str | Path, groups: dict[str, list[Path]], configs: dict[str, RunConfig],
                 generations: int | None = None, title: str = "", level: float = 0.95,
                 summary_path: str | Path | None = None, extra: dict | None = None) -> dict:
    """Draw the figures into ``<out_md dir>/figures/``, write ``summary.json`` and the Markdown report."""
    out_md = Path(out_md)
    root = out_md.parent
    metrics = {k: load_runs(dirs, generations) for k, dirs in groups.items()}
    env = next(iter(configs.values())).env if configs else ""
    title = title or f"Benchmark on {env}"
    summary = {**(extra or {}), **summarize(metrics, level)}
    fig4 = plot_reward_bands(metrics, root / "figures" / FIG4, title=title, level=level)
    fig5 = plot_mphi_losses(metrics, root / "figures" / FIG5, title=f"{env}: M_phi loss", level=level)
    rel = {"fig4": fig4.relative_to(root).as_posix(), "fig5": fig5.relative_to(root).as_posix() if fig5 else None}
    runs = {k: [_rel(d, root) for d in dirs] for k, dirs in groups.items()}
    summary["figures"] = rel
    summary["runs"] = runs
    summary["settings"] = {k: method_settings(c) for k, c in configs.items()}
    if "ppo" in configs:
        from shaped_es.baselines.ppo_settings import ppo_settings

        summary["ppo_settings"] = asdict(ppo_settings(configs["ppo"]))
    summary_path = Path(summary_path) if summary_path else root / "summary.json"
    atomic_write_text(summary_path, json.dumps(summary, indent=2))
    atomic_write_text(out_md, render_markdown(summary, rel, runs, summary["settings"], title))
    return {"report": str(out_md), "summary": str(summary_path), "fig4": str(fig4),
            "fig5": str(fig5) if fig5 else None}


def _rel(d: Path, root: Path) -> str:
    try:
        return Path(d).resolve().relative_to(root.resolve()).as_posix()
    except ValueError:
        return str(d)
