"""``shaped-es benchmark``, ``report`` and ``render``: parsers and handlers for ``cli.py`` to wire in.

Each ``cmd_*`` returns an exit code and prints one JSON line; bad input raises ``ConfigError`` /
``StoreError`` / ``EnvSpecError``, which the CLI prints as one line with exit code 2.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

DEFAULT_METHODS = "shaped,vanilla,cmaes,ppo"
FIGURE_SUFFIXES = (".png", ".pdf", ".svg", ".jpg", ".jpeg")


# -- benchmark -------------------------------------------------------------------------------------------
def add_benchmark_parser(sub) -> argparse.ArgumentParser:
    from shaped_es.executors import EXECUTORS

    b = sub.add_parser("benchmark", help="run every (method, seed), then write summary.json and report.md")
    b.add_argument("--env", required=True, help="Gymnasium id, e.g. CarNav-v0 or Pendulum-v1")
    b.add_argument("--methods", default=DEFAULT_METHODS,
                   help=f"comma-separated methods or --variant names (default {DEFAULT_METHODS})")
    b.add_argument("--variant", action="append", default=[], metavar="NAME=METHOD,KEY=VALUE,...",
                   help="a named setting of a method, compared as a method of its own, e.g. "
                        "lean=shaped,shaping.cloning.steps=5 (repeatable)")
    b.add_argument("--seeds", type=int, default=10,
                   help="number of seeds per method (seeds FIRST..FIRST+N-1; default 10)")
    b.add_argument("--first-seed", type=int, default=0, help="first root seed (default 0)")
    b.add_argument("--generations", type=int, help="generations per run (default: the config's)")
    b.add_argument("--out", required=True, help="benchmark directory (rerun to skip finished runs)")
    b.add_argument("--preset", help="env preset (built-in envs: default, paper)")
    b.add_argument("--config", help="YAML config applied to every run (flags override it)")
    b.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a field, e.g. es.sigma=0.1")
    b.add_argument("--executor", choices=tuple(EXECUTORS))
    b.add_argument("--workers", type=int)
    b.add_argument("--address", help="ray: 'auto' or HOST:PORT of a running cluster")
    b.add_argument("--sparse-waypoints", action="store_true",
                   help="ablation: waypoint_spacing x 10 (paper: planner resolution / 10)")
    b.add_argument("--alpha", type=float, help="ablation: es.alpha, Guided-ES isotropic share (paper 0.6)")
    b.add_argument("--eta", type=float, help="ablation: shaping.eta, surrogate normalization (paper 0.01)")
    _add_threshold(b)
    b.add_argument("--quiet", action="store_true", help="no per-run progress display")
    b.set_defaults(fn=cmd_benchmark)
    return b


def _add_threshold(p: argparse.ArgumentParser) -> None:
    p.add_argument("--threshold", type=float,
                   help="success threshold on the test reward (default: CarNav-v0 200, UR5Reach-v0 40, "
                        "other envs the best baseline's final mean)")


def _check_threshold(threshold: float | None) -> None:
    from shaped_es.config import ConfigError

    if threshold is not None and not math.isfinite(threshold):
        raise ConfigError(f"--threshold must be a finite number, got {threshold}")


def cmd_benchmark(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.runner import BenchmarkSpec, run_benchmark
    from shaped_es.config import ConfigError, RunConfig, parse_set, read_yaml

    if a.seeds <= 0 or a.first_seed < 0:
        raise ConfigError("--seeds must be positive and --first-seed non-negative")
    base = read_yaml(a.config) if a.config else {}
    overrides = {k: v for k, v in {"executor": a.executor, "workers": a.workers,
                                   "address": a.address}.items() if v is not None}
    if a.preset is not None:
        overrides["env_kwargs.preset"] = a.preset
    overrides.update(parse_set(a.set))
    generations = a.generations if a.generations is not None else base.get(
        "generations", RunConfig.model_fields["generations"].default)
    _check_threshold(a.threshold)
    variants = {}
    for text in a.variant:
        label, _, rest = text.partition("=")
        method, *sets = [x.strip() for x in rest.split(",")] if rest else [""]
        variants[label.strip()] = {"method": method, **parse_set([x for x in sets if x])}
    spec = BenchmarkSpec(
        env=a.env, methods=tuple(m.strip() for m in a.methods.split(",") if m.strip()),
        seeds=tuple(range(a.first_seed, a.first_seed + a.seeds)), generations=int(generations), base=base,
        overrides=overrides, sparse_waypoints=a.sparse_waypoints, alpha=a.alpha, eta=a.eta,
        threshold=a.threshold, variants=variants,
    )
    res = run_benchmark(spec, a.out, progress=not a.quiet)
    print(json.dumps({k: res.get(k) for k in ("report", "summary", "fig4", "profile", "fig5")}))
    return 0


# -- report ----------------------------------------------------------------------------------------------
def add_report_parser(sub) -> argparse.ArgumentParser:
    r = sub.add_parser("report", help="Fig. 4/5 (mean + CI over seeds, grouped by method) for any runs")
    r.add_argument("run_dirs", nargs="+", help="run directories, or benchmark directories (their runs/)")
    r.add_argument("--out", default="report.png",
                   help="a figure (.png/.pdf/.svg: Fig. 4 there, Fig. 5 beside it) or a .md report")
    r.add_argument("--title", default="", help="figure / report title")
    _add_threshold(r)
    r.set_defaults(fn=cmd_report)
    return r


def expand_run_dirs(paths: list[str]) -> list[Path]:
    """Run directories as given; a benchmark directory stands for every run under its ``runs/``."""
    out: list[Path] = []
    for p in map(Path, paths):
        if not (p / "config.yaml").is_file() and (p / "runs").is_dir():
            out += sorted(d for d in (p / "runs").iterdir() if (d / "config.yaml").is_file())
        else:
            out.append(p)
    return out


def cmd_report(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.markdown import draw_figures, write_report
    from shaped_es.benchmark.summary import group_runs, load_runs, summarize
    from shaped_es.config import ConfigError

    _check_threshold(a.threshold)
    groups, configs = group_runs(expand_run_dirs(a.run_dirs))
    out = Path(a.out)
    suffix = out.suffix.lower()
    if suffix == ".md":
        print(json.dumps(write_report(out, groups, configs, title=a.title, threshold=a.threshold)))
        return 0
    if suffix not in FIGURE_SUFFIXES:
        raise ConfigError(f"--out must end in .md or one of {', '.join(FIGURE_SUFFIXES)}, got {out.name}")
    metrics = {k: load_runs(dirs) for k, dirs in groups.items()}
    first = next(iter(configs.values()))
    summary = summarize(metrics, threshold=a.threshold, config=first)
    figs = draw_figures(metrics, summary, {"fig4": out, "profile": out.with_name(f"{out.stem}_profile{out.suffix}"),
                                           "fig5": out.with_name(f"{out.stem}_mphi{out.suffix}")},
                        first.env, a.title)
    print(json.dumps({k: str(f) if f else None for k, f in figs.items()}))
    return 0


# -- render ----------------------------------------------------------------------------------------------
def add_render_parser(sub) -> argparse.ArgumentParser:
    r = sub.add_parser("render", help="write a rollout of a run's trained policy as a GIF")
    r.add_argument("run_dir")
    r.add_argument("--out", default="video.gif", help="output .gif")
    r.add_argument("--policy", choices=("best", "mean"), default="best")
    r.add_argument("--episodes", type=int, default=1)
    r.add_argument("--seed", type=int, default=12345, help="seed of the rendered episodes")
    r.add_argument("--max-steps", type=int, help="cap on steps per episode")
    r.add_argument("--fps", type=float, default=30.0)
    r.add_argument("--every", type=int, default=1, help="keep every N-th frame")
    r.set_defaults(fn=cmd_render)
    return r


def cmd_render(a: argparse.Namespace) -> int:
    from shaped_es.render import render_run

    res = render_run(a.run_dir, a.out, episodes=a.episodes, which=a.policy, seed=a.seed,
                     max_steps=a.max_steps, fps=a.fps, every=a.every)
    print(json.dumps(res))
    return 0
