"""The benchmark report: figures (Fig. 4, Fig. 5, the performance profile), ``summary.json`` and a
Markdown page beside them.

``write_report`` works on any run directories grouped by method, so ``shaped-es benchmark`` and
``shaped-es report RUN... --out report.md`` produce the same page.
"""

from __future__ import annotations

import json
import math
import os
from pathlib import Path

from shaped_es.benchmark.grouping import method_settings, plain, report_env
from shaped_es.benchmark.numbers import interval as _interval, num as _num, ratio_text
from shaped_es.benchmark.shaping_summary import probe_choices, shaping_lines
from shaped_es.benchmark.summary import LATE_EVALUATIONS, load_runs, summarize
from shaped_es.benchmark.verdict import verdict_lines
from shaped_es.config import RunConfig
from shaped_es.methods import METHODS, resolve
from shaped_es.report.figures import plot_mphi_losses, plot_performance_profile, plot_reward_bands
from shaped_es.report.style import figure_title
from shaped_es.rundir.atomic import clean_stale_temporaries
from shaped_es.rundir.store import atomic_write_text

MPHI_COLUMNS = ("mphi_train_loss", "mphi_fig5_test_loss", "mphi_fit_test_loss", "mphi_test_loss")
FIG4, FIG5, PROFILE = "fig4_test_reward.png", "fig5_mphi_loss.png", "profile_final_reward.png"

# in every report page: ``report`` writes over a page only where it finds this (cli/overwrite.py)
REPORT_MARK = "<!-- a report page written by shaped-es: report and benchmark redraw it -->"


def _reward(s: dict) -> str:
    mean, ci = s["final_test_reward_mean"], s["final_test_reward_ci"]
    if ci is None:
        return _num(mean)
    return f"{_num(mean)} ± {_num((ci[1] - ci[0]) / 2)}"


def _late(s: dict) -> str:
    """The late reward's IQM and interval (``–`` in a summary.json from before it)."""
    if "late_test_reward_iqm" not in s:
        return "–"
    return f"{_num(s['late_test_reward_iqm'])} {_interval(s['late_test_reward_iqm_ci'])}"


def _censored(d: dict, digits: int = 1) -> str:
    return f"{_num(d['mean'], digits)} / {_num(d['median'], digits)}"


def _short_runs(methods: dict, runs: dict[str, list[str]], budget: int) -> list[str]:
    """A paragraph naming the censored runs shorter than the longest (``budget``): each is censored at its
    own budget, so the means of their methods are weaker lower bounds."""
    short = [f"`{name}` ({n} generations)" for k, s in methods.items()
             for name, n, hit in zip(runs.get(k, []), s["to_threshold"].get("budgets", []), s["to_threshold"]["reached"])
             if n < budget and not hit]
    out = [] if not short else [
        "", f"Runs that never reached the threshold in fewer generations than the longest run ({budget}), each "
        f"censored at its own budget + 1, not at {budget + 1}: " + ", ".join(short) + "."]
    lengths = {k: s["to_threshold"].get("budgets") or [] for k, s in methods.items()}
    if len({n for v in lengths.values() for n in v}) > 1:  # a new user's shaped at 30 beside vanilla at 80
        each = [f"{k} {min(v)}" + (f"-{max(v)}" if max(v) > min(v) else "") + (" generations" if i == 0 else "")
                for i, (k, v) in enumerate((k, v) for k, v in lengths.items() if v)]
        out += ["", f"Runs of different lengths: {', '.join(each)}: the final rewards below are each run's last at "
                    f"its own length."]
    return out


def beats(poi: dict, alpha: float = 0.05) -> bool:
    """X beats Y: P(X > Y)'s bootstrap interval lies above 0.5 and the Mann-Whitney p-value < alpha."""
    ci, p = poi.get("ci"), poi.get("p_value")
    return bool(ci and ci[0] > 0.5 and p is not None and p < alpha)


def _table(header: list[str], rows: list[list[str]]) -> list[str]:
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *["| " + " | ".join(r) + " |" for r in rows]]


def _ratio_rows(ratios: dict, level: float, solved: dict[str, int] | None = None) -> list[str]:
    """The success section's ratio table: each method's censored mean generations and wall time to the
    threshold over each other method's, with bootstrap intervals (``summary.ratios_to_threshold``). Where no
    seed of either method reached the threshold (``solved``: successes per method) a ratio of two budgets would
    read as a tie: the cell says so instead (a new user's drone: "1.00x [1.00, 1.00]" read as "as fast")."""
    order = list(ratios)
    pairs = [(x, y, r) for x, per in ratios.items() for y, r in per.items() if order.index(x) < order.index(y)]
    if not pairs:
        return []
    solved = solved or {}

    def cell(d: dict, x: str, y: str) -> str:
        if solved.get(x) == 0 and solved.get(y) == 0:
            return ("n/a: no seed of either reached it (every seed censored; more --generations, or a --threshold "
                    "within the runs' reach, would tell them apart)")
        return ratio_text(d)
    rows = [[f"{x} / {y}", cell(r["generations"], x, y), cell(r["wall_time_s"], x, y)] for x, y, r in pairs]
    return [f"Ratios of the censored means above, with percentile-bootstrap {level:.0%} intervals (each method's "
            "seeds resampled on their own; below 1: the first method needs less):", "",
            *_table(["methods", "generations to threshold", "wall time to threshold"], rows), ""]


def render_markdown(summary: dict, figures: dict[str, str | None], runs: dict[str, list[str]],
                    settings: dict[str, dict], title: str) -> str:
    level, thr, methods = summary["ci_level"], summary["threshold"], summary["methods"]
    budget, poi = summary["budget_generations"], summary["probability_of_improvement"]
    out = [f"# {title}", "", REPORT_MARK, ""]
    seeds = ", ".join(f"{k} {v['seeds']}" for k, v in methods.items())
    out += [f"Methods: {', '.join(methods)}; seeds per method: {seeds}. Intervals: {level:.0%}; Student-t "
            f"over seeds for means and curves, percentile bootstrap ({summary['bootstrap']['resamples']} "
            "resamples, each method's seeds resampled on their own) for the IQM and the probability of "
            "improvement.", ""]
    verdict = verdict_lines(summary)
    if verdict:  # what the benchmark printed as it ended (a new user's crane looked for it here)
        out += ["## Verdict in brief", "", "Each method against Vanilla-ES (else the first method), as the benchmark "
                "printed it as it ended; the tables below hold the numbers.", "", *[f"- {v}" for v in verdict], ""]
    out += ["## Fig. 4: test reward vs generation, env steps, CPU time and wall time", "",
            "Mean across seeds of the test reward (ES: the generation's tested policy over the test episodes, the "
            "search's mean or its best member by the run's rollout.test_policy; "
            "PPO: the deterministic policy on the same test seeds), band: confidence interval. Each seed's "
            "curve is a step function (held between its evaluations) on a common grid, and the mean is drawn "
            "only where every seed has data: from the last seed's first evaluation on (so one seed alone is "
            "never averaged in as if it were all); on the cost panels a seed that finished sooner keeps its "
            "final reward up to the longest seed's end.", "",
            f"![Fig. 4]({figures['fig4']})", ""]
    out += ["## Performance profile of the final test reward", "",
            "Fraction of seeds whose final test reward exceeds tau, per method (band: pointwise bootstrap "
            f"{level:.0%} interval; dashed line: the success threshold). A curve above another everywhere "
            "is better at every level of performance.", "", f"![Performance profile]({figures['profile']})", ""]
    out += ["## Fig. 5: inverse-dynamics model loss", ""]
    if figures.get("fig5"):
        out += ["M_phi train loss (solid), the paper's test loss (dash-dot: labels vs a fully trained policy's "
                "actions, drawn for runs with `shaping.reference_run`) and the held-out fit on the next "
                "generation's own transitions (dashed) vs its training iterations (mean over seeds, CI band).",
                "", f"![Fig. 5]({figures['fig5']})", ""]
    else:
        out += ["_Not drawn: no run logs `mphi_train_loss` / `mphi_fit_test_loss` (the shaped method's "
                "columns)._", ""]
    src = thr.get("source", "")
    if thr.get("method"):
        src += f", {thr['method']}" + (f"; reference method {thr['reference']}" if thr.get("reference") else "")
    out += ["## Success and cost to the threshold", "",
            f"Threshold: test reward >= {_num(thr['value'])} ({src}). A seed succeeds if any of its test "
            f"evaluations reaches it. Costs to the threshold are each seed's first evaluation reaching it, "
            f"**censored**: a seed that never does counts as its own run's generations + 1 (its budget + 1: "
            f"{budget} + 1 = {budget + 1} for a run of {budget} generations) and as its whole run's wall time "
            "and env steps, so the mean / median over all seeds are lower bounds when seeds are censored "
            "(the median is exact while under half are).", *_short_runs(methods, runs, budget), ""]
    header = ["method", "seeds", "success", "generations to threshold (mean / median)",
              "wall time to threshold (s, mean / median)", "env steps to threshold (mean / median)"]
    rows = [[k, str(s["seeds"]), f"{s['successes']}/{s['seeds']} ({_num(s['success_rate'] * 100, 0)}%)",
             _censored(s["to_threshold"]["generations"]), _censored(s["to_threshold"]["wall_time_s"]),
             _censored(s["to_threshold"]["env_steps"], 0)] for k, s in methods.items()]
    out += [*_table(header, rows), ""]
    out += _ratio_rows(summary.get("ratios_to_threshold") or {}, level,
                       {k: s["successes"] for k, s in methods.items()})
    out += ["## Final test reward and cost per run", "",
            "IQM: interquartile mean of the seeds' final test rewards (mean of the middle 50%), robust to a "
            "stray seed; mean ± the Student-t half width. Late reward: the IQM of each seed's mean over its last "
            f"{LATE_EVALUATIONS} test evaluations (steadier than the last alone). Best test reward: each seed's "
            "best, mean over seeds. Costs: a whole run, mean over seeds.", ""]
    header = ["method", "seeds", f"final reward IQM [{level:.0%} CI]", f"final reward mean (± {level:.0%} CI)",
              f"late reward IQM [{level:.0%} CI]", "best test reward", "generations", "env steps", "CPU time (s)",
              "wall time (s)"]
    rows = [[k, str(s["seeds"]), f"{_num(s['final_test_reward_iqm'])} {_interval(s['final_test_reward_iqm_ci'])}",
             _reward(s), _late(s), _num(s["best_test_reward_mean"]), _num(s["generations"], 0), _num(s["env_steps"], 0),
             _num(s["cpu_time_s"], 1), _num(s["wall_time_s"], 1)] for k, s in methods.items()]
    out += [*_table(header, rows), ""]
    out += shaping_lines(methods, {k: s["wall_time_s"] for k, s in methods.items()})
    if len(methods) > 1:
        out += ["## Probability of improvement", "",
                "Row X, column Y: P(X > Y), the chance that a random seed of X ends with a higher final test "
                f"reward than a random seed of Y (ties count half; Mann-Whitney U / (n_X n_Y)), with its "
                f"{level:.0%} bootstrap interval. 0.5 is no difference.", ""]
        names = list(methods)
        rows = [[x, *["–" if x == y else f"{_num(poi[x][y]['p'])} {_interval(poi[x][y]['ci'])}" for y in names]]
                for x in names]
        out += [*_table(["P(row > column)", *names], rows), ""]
        alpha = 1.0 - level
        wins = [f"{x} > {y} (P = {_num(poi[x][y]['p'])}, Mann-Whitney p = {_num(poi[x][y]['p_value'], 3)})"
                for x in names for y in names if x != y and beats(poi[x][y], alpha)]
        n = min(len(s.get("final_test_reward_per_seed") or []) for s in methods.values())
        p_min = 2.0 / math.comb(2 * n, n) if n else 1.0  # two-sided exact Mann-Whitney, n seeds a side
        rule = (f"X beats Y when the interval lies above 0.5 and the two-sided Mann-Whitney test rejects "
                f"equal distributions at p < {alpha:g} (with {n} seeds a side the smallest possible p is "
                f"{p_min:.2g})")
        out += [(f"{rule}: " + "; ".join(wins) + ".") if wins else
                f"{rule}: no pair does, so these seeds show no method beating another.", ""]
    phases = sorted({p for s in methods.values() for p in s["time_split_s"]})
    if phases:
        out += ["## Time per phase", "", "Seconds per run summed over generations, mean over seeds "
                "(`gen_time_s`: whole generations; the others are phases within them, and phases that run "
                "concurrently, such as M_phi training during the rollouts, overlap).", ""]
        out += [*_table(["method", *phases], [[k, *[_num(s["time_split_s"].get(p), 1) for p in phases]]
                                              for k, s in methods.items()]), ""]
    out += ["## Settings", "", "Per method, the settings it uses (a method never reads the others).", "",
            *_table(["method", "settings"], [[k, "; ".join(f"{name} {plain(v)}" for name, v in st.items())]
                                             for k, st in settings.items()]), ""]
    if summary.get("ppo_settings"):
        ppo = ", ".join(f"{k} {plain(v)}" for k, v in summary["ppo_settings"].items())
        out += [f"PPO (Stable-Baselines3, one torch thread): {ppo}; a generation = the whole number of PPO "
                "iterations nearest to one ES generation's largest env-step budget (`gen_env_steps`).", ""]
    out += ["## Runs", ""] + [f"- {k}: " + ", ".join(f"`{r}`" for r in rs) for k, rs in runs.items()] + [""]
    return "\n".join(out)


def draw_figures(metrics: dict[str, list], summary: dict, paths: dict[str, Path], env: str, title: str = "",
                 level: float = 0.95) -> dict[str, Path | None]:
    """Fig. 4, the performance profile and Fig. 5 (None if no run logs M_phi losses) at ``paths``."""
    finals = {k: s["final_test_reward_per_seed"] for k, s in summary["methods"].items()}
    thr = summary["threshold"]["value"]
    with_mphi = {k: rs for k, rs in metrics.items() if any(c in m for m in rs for c in MPHI_COLUMNS)}
    return {
        "fig4": plot_reward_bands(metrics, paths["fig4"], level=level,
                                  title=figure_title("test reward", env, metrics, title)),
        "profile": plot_performance_profile(finals, paths["profile"], level=level, threshold=thr,
                                            title=figure_title("final test reward profile", env, metrics, title)),
        "fig5": plot_mphi_losses(metrics, paths["fig5"], level=level,
                                 title=figure_title("M_phi loss", env, with_mphi, title)),
    }


def write_report(out_md: str | Path, groups: dict[str, list[Path]], configs: dict[str, RunConfig],
                 generations: int | None = None, title: str = "", level: float = 0.95,
                 summary_path: str | Path | None = None, extra: dict | None = None,
                 threshold: float | None = None) -> dict:
    """Draw the figures into ``<out_md dir>/figures/``, write ``summary.json`` and the Markdown report.

    ``threshold``: the success threshold (default: the env's, else the best baseline's final mean);
    ``generations``: the budget (runs are cut to it; censored seeds count as ``generations + 1``)."""
    out_md = Path(out_md)
    root = out_md.parent
    metrics = {k: load_runs(dirs, generations) for k, dirs in groups.items()}
    env, scale = report_env(configs)  # scale: None when the groups' envs differ (no shared default threshold)
    title = title or f"Benchmark on {env}"
    summary = {**(extra or {}), **summarize(metrics, level, threshold=threshold, budget=generations, config=scale)}
    for k, dirs in groups.items():  # which frame and shooting horizon each shaped run's label probe chose
        if k in summary["methods"] and summary["methods"][k].get("shaping"):
            summary["methods"][k]["shaping"]["label_probe"] = probe_choices(dirs)
    figs = draw_figures(metrics, summary, {"fig4": root / "figures" / FIG4, "fig5": root / "figures" / FIG5,
                                           "profile": root / "figures" / PROFILE}, env, title, level)
    rel = {k: f.relative_to(root).as_posix() if f else None for k, f in figs.items()}
    runs = {k: [_rel(d, root) for d in dirs] for k, dirs in groups.items()}
    summary["figures"] = rel
    summary["runs"] = runs
    summary["settings"] = {k: method_settings(c) for k, c in configs.items()}
    for name in dict.fromkeys(c.method for c in configs.values()):  # a method's first group (split: "ppo (<env>)")
        extra = METHODS[name].report_extra  # e.g. PPO's resolved settings (methods.Method.report_extra)
        if extra:
            summary.update(resolve(extra)(next(c for c in configs.values() if c.method == name)))
    summary_path = Path(summary_path) if summary_path else root / "summary.json"
    _drop_undrawn(summary_path, root, rel)
    clean_stale_temporaries(root, (summary_path.name, out_md.name))  # a killed report's (its figures' below)
    clean_stale_temporaries(root / "figures", (FIG4, FIG5, PROFILE))
    atomic_write_text(summary_path, json.dumps(summary, indent=2))
    atomic_write_text(out_md, render_markdown(summary, rel, runs, summary["settings"], title))
    return {"report": str(out_md), "summary": str(summary_path),
            **{k: str(f) if f else None for k, f in figs.items()}}


def _drop_undrawn(summary_path: Path, root: Path, drawn: dict[str, str | None]) -> None:
    """Delete a figure this page drew before (its previous ``summary.json`` lists it, at its fixed name) that the
    redrawn page no longer draws (Fig. 5 once no run logs M_phi's losses): a stale picture beside a page that
    says it was not drawn. Nothing else is deleted: a file the page's summary does not list is not its own."""
    try:
        old = json.loads(summary_path.read_text()).get("figures") or {}
    except (OSError, ValueError, AttributeError):
        return
    own = {f"figures/{name}" for name in (FIG4, FIG5, PROFILE)}
    for key, path in old.items() if isinstance(old, dict) else ():
        if path in own and drawn.get(key) is None:
            (root / path).unlink(missing_ok=True)


def _rel(d: Path, root: Path) -> str:
    """A run's path from the page's folder (``../bench/runs/vanilla_s0`` for runs outside it), so the page's
    links and a later redraw (``cli/overwrite.py``) find it wherever the command ran; absolute where no
    relative path exists (another drive)."""
    try:
        return Path(os.path.relpath(Path(d).resolve(), root.resolve())).as_posix()
    except ValueError:
        return Path(d).resolve().as_posix()
