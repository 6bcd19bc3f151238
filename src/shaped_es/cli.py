"""``shaped-es`` command line: train / resume / evaluate / benchmark / report / render / bench.

Bad input (config, env, run directory, checkpoint) prints one line ``shaped-es: error: ...`` and exits
with code 2; nothing already saved is touched.
"""

from __future__ import annotations

import argparse
import copy
import json
import os
import sys
from pathlib import Path

USAGE_ERROR = 2


def _user_errors() -> tuple[type[BaseException], ...]:
    from shaped_es.config import ConfigError
    from shaped_es.executors import ExecutorError
    from shaped_es.rollout import EnvSpecError
    from shaped_es.store import StoreError

    errs: list[type[BaseException]] = [ConfigError, StoreError, EnvSpecError, ExecutorError]
    try:
        from shaped_es.shaping.trajectories import TrajectoryStoreError

        errs.append(TrajectoryStoreError)
    except ImportError:
        pass
    return tuple(errs)


def _parse_set(items: list[str]) -> dict:
    import yaml

    from shaped_es.config import ConfigError

    out = {}
    for item in items or []:
        if "=" not in item:
            raise ConfigError(f"--set expects KEY=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        out[k.strip()] = yaml.safe_load(v)
    return out


def _pairs_override(pairs: int | None, popsize: int | None) -> dict:
    """``--pairs`` / ``--popsize`` as ``es.pairs`` (population = 2 x pairs, antithetic)."""
    from shaped_es.config import ConfigError

    if popsize is not None:
        if popsize <= 0 or popsize % 2:
            raise ConfigError(f"--popsize must be a positive even number (antithetic pairs: population = "
                              f"2 x pairs), got {popsize}")
        if pairs is not None and pairs * 2 != popsize:
            raise ConfigError(f"--pairs {pairs} and --popsize {popsize} disagree (population = 2 x pairs)")
        return {"es.pairs": popsize // 2}
    return {} if pairs is None else {"es.pairs": pairs}


def cmd_train(a: argparse.Namespace) -> int:
    from shaped_es.config import build_config, merge, read_yaml
    from shaped_es.preflight import check_run
    from shaped_es.store import RunStore

    data = read_yaml(a.config) if a.config else {}
    flags = {"env": a.env, "method": a.method, "generations": a.generations, "seed": a.seed,
             "executor": a.executor, "workers": a.workers, "address": a.address}
    overrides = {k: v for k, v in flags.items() if v is not None}
    overrides.update(_pairs_override(a.pairs, a.popsize))
    if a.preset is not None:
        overrides["env_kwargs.preset"] = a.preset
    overrides.update(_parse_set(a.set))
    cfg = build_config(merge(data, overrides))
    store = RunStore(a.out)
    if store.exists() or (store.root.exists() and not store.root.is_dir()):
        store.create(cfg)  # raises the one-line "already holds a run" / "not a directory" error
    check_run(cfg)  # everything is validated before anything is written
    store.create(cfg)
    return _run(cfg, store, a)


def cmd_resume(a: argparse.Namespace) -> int:
    from shaped_es.benchmark.runner import finished_generations
    from shaped_es.config import ConfigError, build_config, merge
    from shaped_es.store import RunStore

    store = RunStore(a.run_dir)
    cfg = store.read_config()
    if a.generations is not None:
        done = finished_generations(store)
        if a.generations < done:
            raise ConfigError(f"{a.run_dir} has {done} generations done; --generations {a.generations} is "
                              f"fewer (a run cannot be shortened; evaluate it as it is, or train a new one)")
    if a.generations is not None or a.executor is not None or a.workers is not None:
        changes = {k: v for k, v in {"generations": a.generations, "executor": a.executor,
                                     "workers": a.workers}.items() if v is not None}
        cfg = build_config(merge(cfg.model_dump(mode="json"), changes))
        from shaped_es.config import dump_config
        from shaped_es.store import atomic_write_text

        atomic_write_text(store.config_path, dump_config(cfg))
    return _run(cfg, store, a)


def _run(cfg, store, a) -> int:
    if cfg.method == "ppo":
        from shaped_es.baselines.ppo import train_ppo

        train_ppo(cfg, store, progress=not a.quiet)
    else:
        from shaped_es.trainer import Trainer

        Trainer(cfg, store, progress=not a.quiet).run()
    from shaped_es.report import plot_runs

    fig = plot_runs({cfg.method: store.root}, store.figures_dir / "reward.png", title=cfg.env)
    rows = store.read_metrics()
    last = rows[-1] if rows else {}
    print(json.dumps({"run_dir": str(store.root), "generations": len(rows),
                      "test_reward_mean": _num(last.get("test_reward_mean")),
                      "train_reward_mean": _num(last.get("train_reward_mean")), "figure": str(fig)}))
    return 0


def _num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def cmd_evaluate(a: argparse.Namespace) -> int:
    from shaped_es.evaluate import evaluate_run

    print(json.dumps(evaluate_run(a.run_dir, episodes=a.episodes, which=a.policy, seed=a.seed)))
    return 0


def cmd_bench(a: argparse.Namespace) -> int:
    import shaped_es  # noqa: F401
    from shaped_es.benchmarks.env_speed import bench_env
    from shaped_es.rollout import make_env

    make_env(a.env_id, {}).close()  # one clear error for unknown ids before spawning workers
    res = bench_env(a.env_id, num_envs=a.num_envs, workers=a.workers, seconds=a.seconds)
    print(json.dumps(res) if a.json else "\n".join(f"{k}: {v}" for k, v in res.items()))
    return 0


def cmd_bench_executors(a: argparse.Namespace) -> int:
    from shaped_es.benchmarks.executor_overhead import bench_executors

    names = [n.strip() for n in a.executors.split(",") if n.strip()]
    res = bench_executors(tuple(names), env_id=a.env, pairs=a.pairs, workers=a.workers,
                          generations=a.generations)
    print(json.dumps(res) if a.json else json.dumps(res, indent=2))
    return 0


def cmd_bench_shaping(a: argparse.Namespace) -> int:
    from shaped_es.benchmarks.shaping_cost import bench_shaping, format_table

    envs = tuple(e.strip() for e in a.envs.split(",") if e.strip())
    res = bench_shaping(envs, generations=a.generations, warmup=a.warmup, executor=a.executor,
                        workers=a.workers, overrides=_parse_set(a.set))
    print(json.dumps(res) if a.json else format_table(res))
    return 0


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Every option's default in its help; ``None`` defaults (taken from the config) are described in the
    option's own help instead of printing "(default: None)", and a help that names its default already
    gets no second one."""

    def _get_help_string(self, action):
        if action.default is None or "default" in (action.help or "").lower():  # already says it
            return action.help or ""
        return super()._get_help_string(action)

    def _format_action(self, action):
        if not action.help and action.option_strings and action.default not in (None, argparse.SUPPRESS):
            action = copy.copy(action)
            action.help = "(default: %(default)s)"  # an option without help still shows its default
        return super()._format_action(action)


def _use_formatter(parser: argparse.ArgumentParser) -> None:
    """``HelpFormatter`` for the parser and every sub-parser, however deep (added anywhere)."""
    parser.formatter_class = HelpFormatter
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sp in action.choices.values():
                _use_formatter(sp)


def _config_default(dotted: str):
    from shaped_es.config import RunConfig

    model, parts = RunConfig, dotted.split(".")
    for part in parts[:-1]:
        model = model.model_fields[part].default_factory
    field = model.model_fields[parts[-1]]
    return field.default if field.default_factory is None else field.default_factory()


def build_parser() -> argparse.ArgumentParser:
    from shaped_es import __version__
    from shaped_es.config import EXECUTORS, METHODS

    d = _config_default
    p = argparse.ArgumentParser(prog="shaped-es", description="Shaped policy search with evolution strategies")
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    cfg_note = "; flags override --config, which overrides the built-in default"
    t = sub.add_parser("train", help="start a run in a new directory",
                       description="Start a run in a new directory" + cfg_note + ".")
    t.add_argument("--env", help=f"Gymnasium id, e.g. Pendulum-v1, CarNav-v0 or mypkg.envs:MyEnv-v0 "
                   f"(default: {d('env')})")
    t.add_argument("--method", choices=METHODS, help=f"(default: {d('method')})")
    t.add_argument("--generations", type=int, help=f"generations to run (default: {d('generations')})")
    t.add_argument("--seed", type=int, help=f"root seed (default: {d('seed')})")
    t.add_argument("--pairs", type=int, help=f"antithetic pairs, population = 2 x pairs "
                   f"(default: {d('es.pairs')})")
    t.add_argument("--popsize", type=int, help=f"population size, even: sets --pairs to half of it "
                   f"(default: {2 * d('es.pairs')})")
    t.add_argument("--out", required=True, help="run directory (must not hold a run yet)")
    t.add_argument("--executor", choices=EXECUTORS, help=f"(default: {d('executor')})")
    t.add_argument("--workers", type=int, help="worker count (default: all cores)")
    t.add_argument("--address", help="ray: 'auto' or HOST:PORT of a running cluster (default: a private "
                   "local Ray)")
    t.add_argument("--preset", help="env preset (built-in envs: default, paper; default: the env's)")
    t.add_argument("--config", help="YAML config file (default: none, built-in defaults)")
    t.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="override a field, e.g. es.sigma=0.1 (repeatable; default: none)")
    t.add_argument("--quiet", action="store_true", help="no progress display")
    t.set_defaults(fn=cmd_train)

    r = sub.add_parser("resume", help="continue a killed or finished run")
    r.add_argument("run_dir")
    r.add_argument("--generations", type=int,
                   help="extend the run to this many generations (default: the run's config)")
    r.add_argument("--executor", choices=EXECUTORS, help="(default: the run's config)")
    r.add_argument("--workers", type=int, help="(default: the run's config)")
    r.add_argument("--quiet", action="store_true", help="no progress display")
    r.set_defaults(fn=cmd_resume)

    e = sub.add_parser("evaluate", help="evaluate a run's policy on fresh test episodes")
    e.add_argument("run_dir")
    e.add_argument("--episodes", type=int, default=15, help="test episodes")
    e.add_argument("--policy", choices=("best", "mean"), default="best",
                   help="best: the best test reward so far; mean: the latest (ES: the search mean)")
    e.add_argument("--seed", type=int, default=12345, help="seed of the evaluation episodes")
    e.set_defaults(fn=cmd_evaluate)

    from shaped_es.benchmark.cli_commands import add_benchmark_parser, add_render_parser, add_report_parser

    add_benchmark_parser(sub)
    add_report_parser(sub)
    add_render_parser(sub)

    b = sub.add_parser("bench", help="benchmarks that print figures (JSON with --json)")
    bsub = b.add_subparsers(dest="what", required=True)
    be = bsub.add_parser("env", help="env + policy steps per second on all cores")
    be.add_argument("env_id")
    be.add_argument("--num-envs", type=int, default=1024)
    be.add_argument("--workers", type=int)
    be.add_argument("--seconds", type=float, default=6.0)
    be.add_argument("--json", action="store_true")
    be.set_defaults(fn=cmd_bench)
    bx = bsub.add_parser("executors", help="generation time and overhead per executor (population 64)")
    bx.add_argument("--executors", default="process,ray,mpi", help="comma-separated (default: all)")
    bx.add_argument("--env", help="env id (default: CarNav-v0)")
    bx.add_argument("--pairs", type=int, default=32, help="antithetic pairs (population = 2 x pairs)")
    bx.add_argument("--workers", type=int)
    bx.add_argument("--generations", type=int, default=5, help="timed generations (median reported)")
    bx.add_argument("--json", action="store_true", help="one line of JSON")
    bx.set_defaults(fn=cmd_bench_executors)
    from shaped_es.benchmarks import strategy_speed

    bst = bsub.add_parser("strategies", help="ES master per generation (ask + tell + guide) vs policy size")
    strategy_speed.add_arguments(bst)  # --sizes 2.4k,100k,1M --strategies --generations --json ...
    bst.set_defaults(fn=strategy_speed.run_cli)
    bs = bsub.add_parser("shaping", help="a shaped generation vs a vanilla one, side by side, per phase")
    bs.add_argument("--envs", default="CarNav-v0,UR5Reach-v0", help="comma-separated env ids")
    bs.add_argument("--generations", type=int, default=10, help="timed generations (medians reported)")
    bs.add_argument("--warmup", type=int, default=3, help="untimed generations first")
    bs.add_argument("--executor", default="process", choices=("inline", "process"))
    bs.add_argument("--workers", type=int, help="worker processes (default: all cores)")
    bs.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="config override for the shaped run only, e.g. shaping.cloning.steps=5")
    bs.add_argument("--json", action="store_true", help="one line of JSON")
    bs.set_defaults(fn=cmd_bench_shaping)
    _use_formatter(p)
    return p


def _import_from_cwd() -> None:
    """``module:Env-v0`` ids import ``module`` from the working directory too, as ``python -m`` would
    (the console script's ``sys.path`` lacks it); child processes (workers) inherit it via PYTHONPATH."""
    cwd = os.getcwd()
    if cwd not in sys.path and "" not in sys.path:
        sys.path.insert(0, cwd)
    paths = [q for q in os.environ.get("PYTHONPATH", "").split(os.pathsep) if q]
    if cwd not in paths:
        os.environ["PYTHONPATH"] = os.pathsep.join([cwd, *paths])


def main(argv: list[str] | None = None) -> int:
    _import_from_cwd()
    parser = build_parser()
    a = parser.parse_args(argv)
    errors = _user_errors()
    try:
        return int(a.fn(a) or 0)
    except errors as exc:
        print(f"shaped-es: error: {exc}", file=sys.stderr)
        return USAGE_ERROR
    except KeyboardInterrupt:
        run = getattr(a, "out", None) or getattr(a, "run_dir", None)
        if a.command == "benchmark":
            hint = "; rerun the same command to continue (finished runs are skipped)"
        else:
            hint = f"; continue with: shaped-es resume {run}" if run else ""
        print(f"shaped-es: interrupted{hint}", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
