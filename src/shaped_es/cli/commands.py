"""``shaped-es`` command line: train / resume / evaluate / benchmark / report / render / prune / speed (alias
bench), and the commands that explain: config / envs / check-env (``info.py``). Here: the parser, train and
resume, and how a command ends; evaluate, report and render are in ``results.py``, prune in ``prune.py``,
speed in ``speed_commands.py``, benchmark and suite in ``benchmark/cli_commands.py``.

Errors print one line ``shaped-es: error: ...`` and exit with code 2: bad input (config, env, run
directory, checkpoint; nothing already saved is touched), an env that raises or returns non-finite
values (its exception's type and message in the line), a search that went non-finite, a full disk (the
run stays resumable), a run directory another process is writing, a dead MPI worker. The full traceback
goes to ``RUN/error.log`` (when the run directory exists) and, with ``--debug``, to the terminal. An
unexpected internal error is reported the same way with exit code 1. Warnings are one line each,
``shaped-es: warning: ...`` (all of this in ``errors.py``).
"""

from __future__ import annotations

import argparse
import json
import os
import re
import sys
import warnings

from shaped_es.cli.errors import (Terminated, WarningRoute, config_data, continue_hint, error_line, mpi_spawn_command,
                                  on_signals, restore_signals, supervise)
from shaped_es.cli.results import (  # noqa: F401 - add_report_parser, add_render_parser: importable from here too
    RUN_DIR_HELP,
    add_evaluate_parser,
    add_render_parser,
    add_report_parser,
)
from shaped_es.cli.speed_commands import add_speed_parser



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
    from shaped_es.api import prepare_run
    from shaped_es.config import build_config, merge, parse_set

    data = config_data(a)
    flags = {"env": a.env, "method": a.method, "generations": a.generations, "seed": a.seed,
             "executor": a.executor, "workers": a.workers, "address": a.address, "stop_at": a.stop_at,
             "wandb.enabled": a.wandb or None}
    overrides = {k: v for k, v in flags.items() if v is not None}
    overrides.update(_pairs_override(a.pairs, a.popsize))
    if a.preset is not None:
        overrides["env_kwargs.preset"] = a.preset
    overrides.update(parse_set(a.set))
    cfg = build_config(merge(data, overrides))
    store, probe = prepare_run(cfg, a.out)  # everything is validated before anything is written
    with store.lock():  # one writer; creates the directory (a failed start leaves it retryable)
        store.create(cfg)  # checks again, under the lock, that no other train got there first
        return _run(cfg, store, a, probe)


def cmd_resume(a: argparse.Namespace) -> int:
    from shaped_es.config import ConfigError, build_config, merge
    from shaped_es.rundir.prune import refuse_pruned
    from shaped_es.rundir.store import RunStore, StoreWarning

    store = RunStore(a.run_dir)
    store.read_config()  # "not a run directory" before anything is created or locked
    refuse_pruned(store)  # a pruned run (shaped-es prune): one line, nothing changed
    with store.lock():
        cfg = store.read_config()
        loaded = _fitting_checkpoint(cfg, store)  # a foreign or unreadable checkpoint: nothing changes
        edited = store.env_changed(cfg.env)  # a user's env module edited since the run was made: said, not refused
        if edited:
            warnings.warn(f"{edited} changed since {a.run_dir} was made: the run continues on the env as it is now",
                          StoreWarning, stacklevel=2)
        done = int(loaded[1]["generation"]) if loaded else 0
        if a.generations is not None and a.generations < done:
            raise ConfigError(f"{a.run_dir} has {done} generations done; --generations {a.generations} is "
                              f"fewer (a run cannot be shortened; evaluate it as it is, or train a new one)")
        changes = {k: v for k, v in {"generations": a.generations, "executor": a.executor,
                                     "workers": a.workers, "stop_at": a.stop_at}.items() if v is not None}
        if a.no_stop_at:
            changes["stop_at"] = None
        # config.yaml takes the changes once the restore held up (the run loop writes it), not before
        cfg = build_config(merge(cfg.model_dump(mode="json"), changes))
        why = _nothing_to_run(cfg, loaded[1] if loaded else None, a)
        if why is None and loaded and done >= cfg.generations:
            why = (f"{a.run_dir} has all its {done} generations done: nothing ran, its result is printed again "
                   f"(--generations N above {done} continues it)")
        if why is None and loaded and done < cfg.generations and not a.quiet:  # where it picks up (a new user's
            # resume showed only "gen 13/30", with metrics.csv one row shorter than the checkpoint)
            print(f"shaped-es: {a.run_dir}: resuming from its newest checkpoint, {done} of {cfg.generations} "
                  f"generations done (metrics.csv continues from there as an uninterrupted run's would)",
                  file=sys.stderr)
        rc = _run(cfg, store, a)  # restores (and checks) the checkpoint even when nothing is left to run
        if why:
            print(f"shaped-es: {why}", file=sys.stderr)
        return rc


def _nothing_to_run(cfg, meta, a) -> str | None:
    """Why ``resume`` will run no generation although the run is not at its ``generations``: it stopped at
    ``--stop-at`` (an error when ``--generations`` asks for more: ``ConfigError``), with the command that
    continues it; None otherwise."""
    from shaped_es.config import ConfigError
    from shaped_es.run_loop import stopped_at

    if meta is None:
        return None
    done, run = int(meta["generation"]), a.run_dir
    if stopped_at(cfg, meta):
        best = float(meta["best_test_reward"])
        more = a.generations is not None and a.generations > done
        again = f"shaped-es resume {run}{f' --generations {a.generations}' if more else ''}"
        why = (f"{run} ended as finished after {done} generations: a test reward of {best:.2f} reached its "
               f"--stop-at {cfg.stop_at:g}, so nothing {'would run' if more else 'ran'}; to continue it: "
               f"{again} --no-stop-at (or --stop-at R with R above {best:.2f})")
        if more:  # asked for generations that would not run
            raise ConfigError(why)
        return why
    return None  # a run with every generation done: resume reprints its result (--generations extends it)


def _fitting_checkpoint(cfg, store):
    """The run's newest checkpoint, checked to come from this run's config (``StoreError`` if not)."""
    from shaped_es.rundir.store import StoreError
    from shaped_es.rundir.meta import checkpoint_mismatch

    loaded = store.load_checkpoint()
    if loaded is not None:
        meta = loaded[1]
        if (why := checkpoint_mismatch(meta, cfg, cfg.method, store.config_path)) is not None:
            raise StoreError(f"checkpoint gen_{meta['generation']:06d} in {store.ckpt_dir} was made with a "
                             f"different config than {store.config_path}{why}")
    return loaded


def _run(cfg, store, a, probe=None) -> int:
    from shaped_es.methods import METHODS, resolve

    from shaped_es.trained.video import with_video

    from shaped_es.envs.thresholds import env_threshold
    from shaped_es.monitor.threshold import ThresholdNotice

    thr = env_threshold(cfg)  # (value, where it comes from) or None
    notice = ThresholdNotice(*thr) if thr is not None else None
    callbacks = with_video(cfg, [notice] if notice is not None and not a.quiet else None, progress=not a.quiet)
    resolve(METHODS[cfg.method].train)(cfg, store, progress=not a.quiet, probe=probe, callback=callbacks)
    from shaped_es.report import plot_runs

    fig = plot_runs({cfg.method: store.root}, store.figures_dir / "reward.png", title=cfg.env)
    rows = store.read_metrics()
    last = rows[-1] if rows else {}
    out = {"run_dir": str(store.root), "generations": len(rows),
           "test_reward_mean": _num(last.get("test_reward_mean")),
           "train_reward_mean": _num(last.get("train_reward_mean")), "figure": str(fig)}
    if thr is not None:  # the env's threshold and the first generation reaching it, as a benchmark counts it
        from shaped_es.benchmark.summary import first_reach
        from shaped_es.report.plots import load_metrics

        hit = first_reach(load_metrics(store.root), thr[0])
        out["threshold"] = {"value": thr[0], "source": thr[1],
                            "first_generation": int(hit["generations"]) if hit else None}
    shaping = rows_summary(rows)  # candidate runs: what the labels did
    if shaping is not None:
        from shaped_es.guides.label_budget import run_cost
        from shaped_es.guides.shaped_setup import read_wrap_file

        shaping["cost"] = run_cost(rows, store.root)  # its wall seconds, about (None: no price)

        if (wrap := read_wrap_file(store.root)) is not None:  # a position that wraps (rollout/periodic.py)
            shaping["position_period"] = wrap
        out["shaping"] = shaping
        from shaped_es.guides.label_budget import never_accepted, shaping_line

        line = never_accepted(shaping, METHODS[cfg.method].base) or shaping_line(shaping, len(rows))
        if line is not None:
            print(f"shaped-es: {store.root.name}: {line}", file=sys.stderr)
    print(json.dumps(out))
    return 0


def rows_summary(rows):
    from shaped_es.guides.label_budget import rows_summary as summary

    return summary(rows)


def _num(v):
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def _config_default(dotted: str):
    from shaped_es.config import RunConfig

    model, parts = RunConfig, dotted.split(".")
    for part in parts[:-1]:
        model = model.model_fields[part].default_factory
    field = model.model_fields[parts[-1]]
    return field.default if field.default_factory is None else field.default_factory()


def build_parser() -> argparse.ArgumentParser:
    from shaped_es import __version__
    from shaped_es.config import set_item
    from shaped_es.executors import EXECUTORS
    from shaped_es.methods import METHODS

    d = _config_default
    from shaped_es.cli.info import Parser, use_formatter

    p = Parser(prog="shaped-es", description="Shaped policy search with evolution strategies")
    p.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    p.add_argument("--debug", action="store_true",
                   help="print full tracebacks of errors (accepted anywhere on the command line; they also "
                   "go to RUN/error.log)")
    sub = p.add_subparsers(dest="command", required=True)

    cfg_note = "; flags override --config, which overrides the built-in default"
    t = sub.add_parser("train", help="start a run in a new directory",
                       description="Start a run in a new directory" + cfg_note + ".")
    t.add_argument("--env", help=f"Gymnasium id, e.g. Pendulum-v1, CarNav-v0 or mypkg.envs:MyEnv-v0 "
                   f"(default: {d('env')})")
    t.add_argument("--method", choices=tuple(METHODS), metavar="{" + ",".join(METHODS) + "}",
                   help="; ".join(f"{k}: {m.about}" for k, m in METHODS.items()) + f" (default: {d('method')})")
    t.add_argument("--generations", type=int, help=f"generations to run (default: {d('generations')})")
    t.add_argument("--seed", type=int, help=f"root seed (default: {d('seed')})")
    t.add_argument("--pairs", type=int, help=f"antithetic pairs, population = 2 x pairs "
                   f"(default: {d('es.pairs')})")
    t.add_argument("--popsize", type=int, help=f"population size, even: sets --pairs to half of it "
                   f"(default: {2 * d('es.pairs')})")
    t.add_argument("--out", required=True, help="run directory (must not hold a run yet)")
    t.add_argument("--executor", choices=tuple(EXECUTORS), help=f"where rollouts run: inline (this process), "
                   f"process (local workers), ray, mpi (default: {d('executor')})")
    t.add_argument("--workers", type=int, help="worker count (default: all cores)")
    t.add_argument("--address", help="ray: 'auto' or HOST:PORT of a running cluster (default: a private "
                   "local Ray)")
    t.add_argument("--preset", help="env preset (built-in envs: default, paper; default: the env's)")
    t.add_argument("--config", help="YAML config file (default: none, built-in defaults)")
    t.add_argument("--set", action="append", metavar="KEY=VALUE", type=set_item,
                   help="override a config field, e.g. es.sigma=0.1 (repeatable; every field: shaped-es config; "
                   "default: none)")
    t.add_argument("--stop-at", type=float, metavar="R",
                   help="end the run, as finished, once a test reward reaches R (default: run every generation)")
    t.add_argument("--wandb", action="store_true",
                   help="also log to Weights & Biases (pip install 'shaped-es[wandb]'; offline: WANDB_MODE=offline "
                   "or --set wandb.mode=offline)")
    t.add_argument("--quiet", action="store_true", help="no progress display")
    t.set_defaults(fn=cmd_train)

    r = sub.add_parser("resume", help="continue a killed or finished run")
    r.add_argument("run_dir", help=RUN_DIR_HELP)
    r.add_argument("--generations", type=int,
                   help="extend the run to this many generations (default: the run's config)")
    r.add_argument("--executor", choices=tuple(EXECUTORS), help="where rollouts run (default: the run's config)")
    r.add_argument("--workers", type=int, help="worker count (default: the run's config)")
    stop = r.add_mutually_exclusive_group()
    stop.add_argument("--stop-at", type=float, metavar="R",
                      help="end the run once a test reward reaches R; a run --stop-at ended continues if R is "
                      "above its best test reward (default: the run's config)")
    stop.add_argument("--no-stop-at", action="store_true",
                      help="run every generation: continue a run that --stop-at ended")
    r.add_argument("--quiet", action="store_true", help="no progress display")
    r.set_defaults(fn=cmd_resume)

    add_evaluate_parser(sub)
    from shaped_es.benchmark.cli_commands import add_benchmark_parser, add_suite_parser

    add_benchmark_parser(sub)
    add_suite_parser(sub)
    add_report_parser(sub)
    add_render_parser(sub)
    from shaped_es.cli.prune import add_prune_parser

    add_prune_parser(sub)
    from shaped_es.cli import info as cli_info

    cli_info.add_parsers(sub)  # config, envs, check-env

    add_speed_parser(sub)
    use_formatter(p)
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


_NEGATIVE = re.compile(r"-(\d+\.?\d*|\.\d+)(e[+-]?\d+)?|-inf(inity)?", re.IGNORECASE)


def _numeric_flags(parser: argparse.ArgumentParser) -> set[str]:
    """The options, of every subcommand, that take one number (``--stop-at R``)."""
    out: set[str] = set()
    for action in parser._actions:  # noqa: SLF001 - argparse has no public walk
        if isinstance(action, argparse._SubParsersAction):  # noqa: SLF001
            for sub in action.choices.values():
                out |= _numeric_flags(sub)
        elif action.type in (int, float) and action.nargs is None:
            out.update(o for o in action.option_strings if o.startswith("--"))
    return out


def join_negative_numbers(argv: list[str], flags: set[str]) -> list[str]:
    """``--stop-at -1e9`` as ``--stop-at=-1e9``: argparse takes a word like ``-1e9`` for an option."""
    out, i = [], 0
    while i < len(argv):
        if argv[i] in flags and i + 1 < len(argv) and _NEGATIVE.fullmatch(argv[i + 1]):
            out.append(f"{argv[i]}={argv[i + 1]}")
            i += 2
        else:
            out.append(argv[i])
            i += 1
    return out


def main(argv: list[str] | None = None) -> int:
    _import_from_cwd()
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    parser = build_parser()
    argv = join_negative_numbers(argv, _numeric_flags(parser))
    a = parser.parse_args([x for x in argv if x != "--debug"])
    old_show = warnings.showwarning
    route = WarningRoute(a, debug)
    warnings.showwarning = route.show
    old_signals = on_signals()  # SIGTERM as Ctrl-C: clean-up, one line; a second signal: no more lines
    try:
        if mpi_spawn_command(a):
            return supervise(a, argv, debug)
        return int(a.fn(a) or 0)
    except BrokenPipeError:  # the output's reader went away (| head): not an error of the command
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    except KeyboardInterrupt as exc:
        hint = continue_hint(a)
        route.flush()
        what, code = ("terminated (SIGTERM)", 143) if isinstance(exc, Terminated) else ("interrupted", 130)
        print(f"shaped-es: {what}{'; ' + hint if hint else ''}", file=sys.stderr)
        route.release_interrupted(exc)
        return code
    except Exception as exc:  # noqa: BLE001 - every error is one line (traceback: --debug, error.log)
        line, code = error_line(exc, a, debug)
        route.flush()  # other libraries' warnings: one line before the error's (their text in error.log)
        print(line, file=sys.stderr)
        return code
    finally:
        envs = sys.modules.get("shaped_es.rollout.worker_envs")  # loaded: the command ran episodes in this process
        if envs is not None:
            envs.drop_envs()  # before the route closes: a warning of an env's close goes to error.log too
        route.close()
        warnings.showwarning = old_show
        restore_signals(old_signals)


if __name__ == "__main__":
    sys.exit(main())
