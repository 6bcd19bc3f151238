"""``shaped-es benchmark``: its parser and handler for ``cli/commands.py`` to wire in, and the
``--threshold`` option it shares with ``shaped-es report`` (in ``cli/commands.py``).

``cmd_benchmark`` returns an exit code and prints one JSON line; bad input raises ``ConfigError`` /
``StoreError`` / ``EnvSpecError``, which the CLI prints as one line with exit code 2.
"""

from __future__ import annotations

import argparse
import json
import math
import re

DEFAULT_METHODS = "shaped,vanilla,cmaes,ppo"


# -- benchmark -------------------------------------------------------------------------------------------
def add_benchmark_parser(sub) -> argparse.ArgumentParser:
    from shaped_es.config import set_item
    from shaped_es.executors import EXECUTORS

    b = sub.add_parser("benchmark", help="run every (method, seed), then write summary.json and report.md")
    b.add_argument("--env", required=True, help="Gymnasium id, e.g. CarNav-v0 or Pendulum-v1")
    b.add_argument("--methods", default=DEFAULT_METHODS,
                   help=f"comma-separated methods or --variant names (default {DEFAULT_METHODS})")
    b.add_argument("--variant", action="append", default=[], metavar="NAME=METHOD,KEY=VALUE,...",
                   help="a named setting of a method, compared as a method of its own, e.g. "
                        "lean=shaped,shaping.cloning.steps=5 (repeatable)")
    b.add_argument("--grid", action="append", default=[], metavar="KEY=V1,V2,...",
                   help="a sweep: every combination of these values (repeatable, one key each) becomes a "
                        "variant of each --methods method, named METHOD-key1V1-key2V2 (default: none)")
    b.add_argument("--sample", type=int, metavar="N",
                   help="with --grid: N combinations drawn at random (seeded by --first-seed) instead of all "
                        "(default: all)")
    b.add_argument("--seeds", type=seeds_arg, default=10,
                   help="number of seeds per method (seeds FIRST..FIRST+N-1; default 10), or a range A-B "
                        "(seeds A..B)")
    b.add_argument("--first-seed", type=int, help="first root seed (default 0)")
    b.add_argument("--generations", type=int, help="generations per run (default: the config's)")
    b.add_argument("--out", help="benchmark directory (rerun to skip finished runs); required unless "
                   "--estimate-only (default: none; with --estimate-only, its finished runs count as done)")
    b.add_argument("--preset", help="env preset (built-in envs: default, paper; default: the env's)")
    b.add_argument("--config", help="YAML config applied to every run, flags override it (default: none, "
                   "the built-in defaults)")
    b.add_argument("--set", action="append", metavar="KEY=VALUE", type=set_item,
                   help="override a config field of every run, e.g. es.sigma=0.1 (repeatable; every field: "
                   "shaped-es config; default: none)")
    b.add_argument("--executor", choices=tuple(EXECUTORS),
                   help="where the ES methods' rollouts run (PPO: one process) (default: the config's, process)")
    b.add_argument("--workers", type=int, help="worker count (default: all cores)")
    b.add_argument("--address", help="ray: 'auto' or HOST:PORT of a running cluster (default: a private "
                   "local Ray)")
    b.add_argument("--sparse-waypoints", action="store_true",
                   help="ablation: waypoint_spacing x 10 (paper: planner resolution / 10)")
    b.add_argument("--alpha", type=float, help="ablation: es.alpha, Guided-ES isotropic share (paper 0.6; "
                   "default: the config's, 0.9)")
    b.add_argument("--eta", type=float, help="ablation: shaping.eta, surrogate normalization (default: the "
                   "config's, 0.01 as the paper)")
    add_threshold(b)
    b.add_argument("--stop-at", type=float, metavar="R",
                   help="end each run, as finished, once a test reward reaches R (default: every generation; "
                   "final rewards are then the first ones reaching R)")
    b.add_argument("--wandb", action="store_true",
                   help="log every run to Weights & Biases, grouped by the benchmark's directory name")
    b.add_argument("--no-estimate", action="store_true",
                   help="start without first timing each method for the cost estimate")
    b.add_argument("--estimate-only", action="store_true",
                   help="print what the benchmark would cost (a short timing per method) and stop, writing nothing")
    b.add_argument("--quiet", action="store_true", help="no per-run progress display")
    b.set_defaults(fn=cmd_benchmark)
    return b


# -- suite -----------------------------------------------------------------------------------------------
def add_suite_parser(sub) -> argparse.ArgumentParser:
    from shaped_es.benchmark.suite import DEFAULT_METHODS as SUITE_METHODS
    from shaped_es.benchmark.suite import DEFAULT_SUITE, SUITES
    from shaped_es.config import set_item
    from shaped_es.executors import EXECUTORS

    s = sub.add_parser("suite", help="the suite study: a benchmark per task of a waypoint task suite, one table")
    ssub = s.add_subparsers(dest="what", required=True)
    r = ssub.add_parser("run", help="run every (task, method, seed) resumably, then write suite.md / suite.json")
    r.add_argument("--out", required=True, help="suite directory (rerun to skip finished runs)")
    r.add_argument("--suite", default=DEFAULT_SUITE, choices=tuple(SUITES), help=f"(default {DEFAULT_SUITE})")
    r.add_argument("--tasks", help="comma-separated env ids of the suite (default: all; shaped-es suite list)")
    r.add_argument("--methods", default=",".join(SUITE_METHODS),
                   help=f"comma-separated methods (default {','.join(SUITE_METHODS)})")
    r.add_argument("--seeds", type=seeds_arg, default=10,
                   help="seeds per method (FIRST..FIRST+N-1; default 10), or a range A-B (seeds A..B)")
    r.add_argument("--first-seed", type=int, help="first root seed (default 0)")
    r.add_argument("--generations", type=int,
                   help="generations of every run (default: each task's budget in the suite, shaped-es suite list)")
    r.add_argument("--set", action="append", metavar="KEY=VALUE", type=set_item,
                   help="override a config field of every run, e.g. es.sigma=0.1 (repeatable; default: none)")
    r.add_argument("--executor", choices=tuple(EXECUTORS), help="where rollouts run (default: process)")
    r.add_argument("--workers", type=int, help="worker count (default: all cores)")
    r.add_argument("--estimate-only", action="store_true",
                   help="print what the suite would cost (a short timing per task and method) and stop")
    r.add_argument("--quiet", action="store_true", help="no per-run progress display (the [suite] lines stay)")
    r.set_defaults(fn=cmd_suite_run)
    rep = ssub.add_parser("report", help="write DIR/suite.md and DIR/suite.json from a suite's runs")
    rep.add_argument("dir", help="suite directory (of shaped-es suite run)")
    rep.set_defaults(fn=cmd_suite_report)
    ls = ssub.add_parser("list", help="the suites' tasks and generation budgets")
    ls.set_defaults(fn=cmd_suite_list)
    return s


def cmd_suite_run(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.suite import run_suite
    from shaped_es.config import ConfigError, parse_set

    seeds = seed_list(a.seeds, a.first_seed)
    if a.generations is not None and a.generations <= 0:
        raise ConfigError(f"--generations must be positive, got {a.generations}")
    overrides = {k: v for k, v in {"executor": a.executor, "workers": a.workers}.items() if v is not None}
    overrides.update(parse_set(a.set))
    res = run_suite(a.out, suite=a.suite, tasks=[t.strip() for t in a.tasks.split(",") if t.strip()] if a.tasks
                    else None, methods=tuple(m.strip() for m in a.methods.split(",") if m.strip()),
                    seeds=seeds, generations=a.generations,
                    overrides=overrides, progress=not a.quiet, estimate_only=a.estimate_only)
    print(json.dumps(res))
    return 0


def cmd_suite_report(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.suite import write_suite_report

    print(json.dumps(write_suite_report(a.dir)))
    return 0


def cmd_suite_list(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.suite import SUITES
    from shaped_es.benchmark.summary import builtin_threshold

    for name, tasks in SUITES.items():
        print(f"{name}:")
        for t in tasks:
            thr = builtin_threshold(t.env)
            print(f"  {t.env:<15} {t.generations:>4} generations  threshold {thr[0] if thr else '-':<6}  {t.note}")
    return 0


def seeds_arg(text: str) -> int | tuple[int, int]:
    """``--seeds``: a count (``10``) or an inclusive range (``0-9``, ``100-109``: two new users typed it)."""
    m = re.fullmatch(r"\s*(\d+)\s*-\s*(\d+)\s*", text)
    if m:
        lo, hi = int(m.group(1)), int(m.group(2))
        if hi < lo:
            raise argparse.ArgumentTypeError(f"the range {text!r} ends before it starts (A-B with A <= B)")
        return lo, hi
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is neither a count (10) nor a range of seeds (0-9)") from None


def seed_list(seeds: int | tuple[int, int], first: int | None) -> tuple[int, ...]:
    """The root seeds of ``--seeds`` (a count from ``--first-seed``, default 0, or a range) -> a tuple."""
    from shaped_es.config import ConfigError

    if isinstance(seeds, tuple):
        if first is not None and first != seeds[0]:
            raise ConfigError(f"--seeds {seeds[0]}-{seeds[1]} names its first seed; --first-seed {first} "
                              f"disagrees (give one of them)")
        return tuple(range(seeds[0], seeds[1] + 1))
    first = 0 if first is None else first
    if seeds <= 0 or first < 0:
        raise ConfigError("--seeds must be positive and --first-seed non-negative")
    return tuple(range(first, first + seeds))


def add_threshold(p: argparse.ArgumentParser) -> None:
    p.add_argument("--threshold", type=float,
                   help="success threshold on the test reward (default: the reward_threshold registered on "
                        "the env's Gymnasium spec, an own env's too, e.g. CarNav-v0 200, UR5Reach-v0 40, "
                        "PointVel-v0 8.5; an env without one: the best baseline's final mean)")


def check_threshold(threshold: float | None) -> None:
    from shaped_es.config import ConfigError

    if threshold is not None and not math.isfinite(threshold):
        raise ConfigError(f"--threshold must be a finite number, got {threshold}")


def _split_top_level(text: str) -> list[str]:
    """``text`` split at the commas outside brackets, so a variant's value may be a YAML list
    (``shaping.mean_clone.scales=[0.3,1.0]``)."""
    parts, depth, start = [], 0, 0
    for i, ch in enumerate(text):
        depth += {"[": 1, "{": 1, "]": -1, "}": -1}.get(ch, 0)
        if ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    return parts + [text[start:]]


def grid_variants(methods: list[str], grid: list[str], sample: int | None = None,
                  seed: int = 0) -> dict[str, dict]:
    """``--grid`` as benchmark variants: each combination of the keys' values (all, or ``sample`` drawn
    without replacement) for each method, named ``METHOD-<key>V-...`` by each key's last part (its whole
    dotted path where two keys share a last part). One entry per combination: ``{"method": m, key: v}``."""
    import itertools

    import numpy as np

    from shaped_es.config import ConfigError, parse_set

    axes: list[tuple[str, list[str]]] = []
    for text in grid:
        key, sep, values = text.partition("=")
        vals = [v.strip() for v in _split_top_level(values) if v.strip()] if sep else []
        if not key.strip() or not vals:
            raise ConfigError(f"--grid {text!r}: expected KEY=V1,V2,... (e.g. es.sigma=0.05,0.1)")
        if key.strip() in [k for k, _ in axes]:
            raise ConfigError(f"--grid names {key.strip()!r} twice; give its values in one --grid")
        axes.append((key.strip(), vals))
    lasts = [k.rsplit(".", 1)[-1] for k, _ in axes]
    names = [k.rsplit(".", 1)[-1] if lasts.count(k.rsplit(".", 1)[-1]) == 1 else k.replace(".", "_")
             for k, _ in axes]
    combos = list(itertools.product(*[v for _, v in axes]))
    if sample is not None:
        if not 0 < sample <= len(combos):
            raise ConfigError(f"--sample must be between 1 and the grid's {len(combos)} combinations, got {sample}")
        pick = np.random.default_rng(seed).choice(len(combos), size=sample, replace=False)
        combos = [combos[i] for i in sorted(pick)]
    out = {}
    for m in methods:
        for combo in combos:
            label = "-".join([m] + [f"{n}{v}".replace("/", "_") for n, v in zip(names, combo)])
            out[label] = {"method": m, **parse_set([f"{k}={v}" for (k, _), v in zip(axes, combo)])}
    return out


def cmd_benchmark(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.runner import run_benchmark
    from shaped_es.benchmark.spec import BenchmarkSpec
    from shaped_es.config import ConfigError, RunConfig, parse_set, read_yaml

    seeds = seed_list(a.seeds, a.first_seed)
    if a.out is None and not a.estimate_only:
        raise ConfigError("benchmark needs --out DIR, the benchmark directory (only --estimate-only, which "
                          "writes nothing, runs without it)")
    base = read_yaml(a.config) if a.config else {}
    overrides = {k: v for k, v in {"executor": a.executor, "workers": a.workers, "address": a.address,
                                   "stop_at": a.stop_at}.items() if v is not None}
    if a.wandb and a.out is not None:
        from pathlib import Path

        overrides.update({"wandb.enabled": True, "wandb.group": Path(a.out).resolve().name})
    if a.preset is not None:
        overrides["env_kwargs.preset"] = a.preset
    overrides.update(parse_set(a.set))
    generations = a.generations if a.generations is not None else base.get(
        "generations", RunConfig.model_fields["generations"].default)
    check_threshold(a.threshold)
    variants = {}
    for text in a.variant:
        label, _, rest = text.partition("=")
        method, *sets = [x.strip() for x in _split_top_level(rest)] if rest else [""]
        variants[label.strip()] = {"method": method, **parse_set([x for x in sets if x])}
    methods = tuple(m.strip() for m in a.methods.split(",") if m.strip())
    if a.sample is not None and not a.grid:
        raise ConfigError("--sample draws from a --grid; give one (e.g. --grid es.sigma=0.05,0.1)")
    if a.grid:  # a sweep: the grid's combinations are the methods compared
        swept = grid_variants([m for m in methods if m not in variants], a.grid, a.sample, seeds[0])
        variants.update(swept)
        methods = tuple(swept)
    spec = BenchmarkSpec(
        env=a.env, methods=methods,
        seeds=seeds, generations=int(generations), base=base,
        overrides=overrides, sparse_waypoints=a.sparse_waypoints, alpha=a.alpha, eta=a.eta,
        threshold=a.threshold, variants=variants,
    )
    if a.out is None:  # --estimate-only without a benchmark directory: every run is still to do
        import tempfile
        from pathlib import Path

        with tempfile.TemporaryDirectory(prefix="shaped-es-estimate-") as tmp:
            res = run_benchmark(spec, Path(tmp) / "benchmark", progress=not a.quiet, estimate_only=True)
    else:
        res = run_benchmark(spec, a.out, progress=not a.quiet, estimate=not a.no_estimate,
                            estimate_only=a.estimate_only)
    keys = ("estimate_s",) if a.estimate_only else ("report", "summary", "fig4", "profile", "fig5")
    print(json.dumps({k: res.get(k) for k in keys}))
    return 0
