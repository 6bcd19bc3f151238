"""``shaped-es evaluate``, ``report`` and ``render``: the commands that use finished runs (a run's policy on
fresh episodes, figures and a report page over runs, a GIF of a rollout)."""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

RUN_DIR_HELP = "a run directory (the --out of train)"
POLICY_HELP = ("best: the policy with the best test reward so far (whichever rollout.test_policy tested); "
               "mean: the latest (ES: the search mean)")
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg")
REPORT_OUT = "shaped-es-report/report.md"  # report's default: never loose files in the working folder


def add_evaluate_parser(sub) -> argparse.ArgumentParser:
    e = sub.add_parser("evaluate", help="evaluate a run's policy on fresh test episodes")
    e.add_argument("run_dir", help=RUN_DIR_HELP)
    e.add_argument("--episodes", type=int, default=15, help="test episodes")
    e.add_argument("--policy", choices=("best", "mean"), default="best", help=POLICY_HELP)
    e.add_argument("--seed", type=int, default=12345, help="seed of the evaluation episodes")
    add_executor_options(e)
    e.set_defaults(fn=cmd_evaluate)
    return e


def add_executor_options(p: argparse.ArgumentParser) -> None:
    """``--executor`` and ``--workers`` as ``train`` takes them (its default: the config's, ``process``)."""
    from shaped_es.config import RunConfig
    from shaped_es.executors import EXECUTORS

    p.add_argument("--executor", choices=tuple(EXECUTORS), default=RunConfig.model_fields["executor"].default,
                   help="where the episodes run: inline (this process), process (local workers), ray, mpi")
    p.add_argument("--workers", type=int, help="worker count (default: all cores)")


def cmd_evaluate(a: argparse.Namespace) -> int:
    from shaped_es.rundir.store import RunStore
    from shaped_es.trained.evaluate import evaluate_run, selection_note

    result = evaluate_run(a.run_dir, episodes=a.episodes, which=a.policy, seed=a.seed, executor=a.executor,
                          workers=a.workers)
    print(json.dumps(result))
    note = selection_note(RunStore(a.run_dir), result)
    if note:
        print(f"shaped-es: {a.run_dir}: {note}", file=sys.stderr)
    return 0


def add_report_parser(sub) -> argparse.ArgumentParser:
    from shaped_es.benchmark.cli_commands import add_threshold

    r = sub.add_parser("report", help="Fig. 4/5 (mean + CI over seeds, grouped by method) for any runs")
    r.add_argument("run_dirs", nargs="+", help="run directories, or benchmark directories (their runs/)")
    r.add_argument("--out", default=REPORT_OUT,
                   help="a .md report page (summary.json and figures/ beside it) or a figure (.png/.pdf/.svg: "
                        f"Fig. 4 there, the profile and Fig. 5 beside it) (default: {REPORT_OUT}, a folder of "
                        "its own)")
    r.add_argument("--title", help="figure / report title (default: the env and the seeds)")
    r.add_argument("--force", action="store_true", help="write over existing files at --out (a page no report "
                   "wrote, another set of runs' report, existing figures)")
    add_threshold(r)
    r.set_defaults(fn=cmd_report)
    return r


def expand_run_dirs(paths: list[str]) -> list[Path]:
    """Run directories as given; a benchmark directory stands for every run under its ``runs/``, in its
    ``benchmark.yaml``'s method order where it has one (a new user's report of one benchmark, sorted by name,
    put CMA-ES first and its ratios upside down: "cmaes / shaped 6.56x"), then by seed."""
    out: list[Path] = []
    for p in map(Path, paths):
        if not (p / "config.yaml").is_file() and (p / "runs").is_dir():
            out += sorted((d for d in (p / "runs").iterdir() if (d / "config.yaml").is_file()),
                          key=_run_order(p))
        else:
            out.append(p)
    return out


def _run_order(bench: Path):
    """Sort key of a benchmark's run directories ``NAME_sSEED``: NAME's place among its ``benchmark.yaml``'s
    methods (unlisted names after them, by name), then SEED as a number."""
    from shaped_es.benchmark.grouping import split_run_name
    from shaped_es.safe_yaml import load

    try:
        methods = [str(m) for m in (load((bench / "benchmark.yaml").read_text()) or {}).get("methods", [])]
    except Exception:  # noqa: BLE001 - no or unreadable benchmark.yaml: by name, as before
        methods = []

    def key(d: Path):
        name, seed = split_run_name(d.name) or (d.name, -1)
        return (methods.index(name) if name in methods else len(methods), name, seed)
    return key


def cmd_report(a: argparse.Namespace) -> int:
    """Fig. 4, the performance profile and Fig. 5 (or, for ``--out x.md``, the benchmark's report page)."""
    from shaped_es.benchmark.cli_commands import check_threshold
    from shaped_es.benchmark.markdown import draw_figures, write_report
    from shaped_es.benchmark.grouping import group_runs, report_env
    from shaped_es.benchmark.summary import load_runs, summarize
    from shaped_es.cli.overwrite import check_free, check_report_page
    from shaped_es.config import ConfigError

    check_threshold(a.threshold)
    groups, configs = group_runs(expand_run_dirs(a.run_dirs))
    out = Path(a.out)
    suffix = out.suffix.lower()
    if suffix == ".md":
        check_report_page(out, [d for dirs in groups.values() for d in dirs], a.force)
        paths = write_report(out, groups, configs, title=a.title or "", threshold=a.threshold)
        from shaped_es.benchmark.verdict import verdict_lines

        where = " ".join(a.run_dirs)
        for line in verdict_lines(json.loads(Path(paths["summary"]).read_text()), where):  # as a benchmark ends
            print(f"[report] {line}", file=sys.stderr)
        print(json.dumps(paths))
        return 0
    if suffix not in FIGURE_SUFFIXES:
        page = out / "report.md" if not suffix else out.with_suffix(".md")  # a folder named: its page
        raise ConfigError(f"--out must end in .md or one of {', '.join(FIGURE_SUFFIXES)}, got {out.name} "
                          f"(a report page: --out {page})")
    targets = {"fig4": out, "profile": out.with_name(f"{out.stem}_profile{out.suffix}"),
               "fig5": out.with_name(f"{out.stem}_mphi{out.suffix}")}
    check_free(list(targets.values()), a.force)
    metrics = {k: load_runs(dirs) for k, dirs in groups.items()}
    env, scale = report_env(configs)
    summary = summarize(metrics, threshold=a.threshold, config=scale)
    figs = draw_figures(metrics, summary, targets, env, a.title or "")
    print(json.dumps({k: str(f) if f else None for k, f in figs.items()}))
    return 0


def add_render_parser(sub) -> argparse.ArgumentParser:
    r = sub.add_parser("render", help="write a rollout of a run's trained policy as a GIF")
    r.add_argument("run_dir", help=RUN_DIR_HELP)
    r.add_argument("--out", default="video.gif", help="output .gif")
    r.add_argument("--policy", choices=("best", "mean"), default="best", help=POLICY_HELP)
    r.add_argument("--episodes", type=int, default=1, help="episodes in the GIF, one after another")
    r.add_argument("--seed", type=int, default=12345,
                   help="seed of the rendered episodes (evaluate's: the same seed gives its first episodes)")
    r.add_argument("--max-steps", type=int,
                   help="cap on steps per episode (default: the run's rollout.max_steps, else the env's limit)")
    r.add_argument("--fps", type=float, default=None, help="frames per second of the GIF (default: the env's "
                   "metadata['render_fps'] over --every, real time; 30 where it has none)")
    r.add_argument("--every", type=int, default=1, help="keep every N-th frame")
    r.add_argument("--force", action="store_true", help="write over an existing --out file")
    r.set_defaults(fn=cmd_render)
    return r


def cmd_render(a: argparse.Namespace) -> int:
    from shaped_es.cli.overwrite import check_free
    from shaped_es.envs.gl import headless_gl
    from shaped_es.trained.render import render_run

    check_free([Path(a.out)], a.force)
    headless_gl()  # before an own env's module imports mujoco (a new user's MuJoCo arm: no display, no frames)
    res = render_run(a.run_dir, a.out, episodes=a.episodes, which=a.policy, seed=a.seed,
                     max_steps=a.max_steps, fps=a.fps, every=a.every)
    print(json.dumps(res))
    return 0
