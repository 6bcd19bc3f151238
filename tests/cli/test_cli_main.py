"""Command-line habits: validation before anything is written (a failed ``train`` does not block its
retry), ``module:Env`` ids from the working directory, defaults in every ``--help``, ``--version``,
``python -m shaped_es``, ``--pairs`` / ``--popsize``, ``resume --generations`` below what is done."""

import argparse
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from helpers import POINT_ENV_MODULE, SRC
from shaped_es import __version__
from shaped_es.cli.commands import build_parser, main

TINY = ["--executor", "inline", "--generations", "2", "--pairs", "2", "--set", "rollout.episodes=1",
        "--set", "rollout.test_episodes=2", "--set", "policy.hidden=[4]", "--set", "tensorboard=false",
        "--quiet"]


def _one_error_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("shaped-es: error: "), err
    return err[0]


def test_failed_train_leaves_nothing_and_the_retry_works(tmp_path, capsys):
    out = tmp_path / "run"
    # CartPole has no info['position'] / info['waypoint']: --method shaped cannot use it
    assert main(["train", "--env", "CartPole-v1", "--method", "shaped", *TINY, "--out", str(out)]) == 2
    assert "info['position']" in _one_error_line(capsys)
    assert not out.exists()
    assert main(["train", "--env", "CartPole-v1", "--method", "shaped", *TINY, "--out", str(out)]) == 2
    capsys.readouterr()
    assert main(["train", "--env", "CartPole-v1", "--method", "vanilla", *TINY, "--out", str(out)]) == 0
    assert (out / "checkpoints" / "latest.json").is_file()
    # and other bad input fails the same way, before writing
    assert main(["train", "--env", "Pendulum-v1", "--method", "ppo", "--set", "ppo.n_steps=1",
                 "--out", str(tmp_path / "p")]) == 2
    assert "n_steps" in _one_error_line(capsys) and not (tmp_path / "p").exists()


def test_benchmark_validates_every_method_before_writing(tmp_path, capsys):
    out = tmp_path / "b"
    assert main(["benchmark", "--env", "CartPole-v1", "--methods", "vanilla,shaped", "--seeds", "1",
                 "--generations", "1", "--executor", "inline", "--quiet", "--out", str(out)]) == 2
    assert "--method shaped" in _one_error_line(capsys)
    assert not out.exists()


def _console_script():
    exe = Path(sys.executable).parent / "shaped-es"
    return str(exe) if exe.is_file() else shutil.which("shaped-es")


@pytest.mark.parametrize("executor", ["inline", "process"])
def test_own_env_module_from_the_working_directory(tmp_path, executor):
    (tmp_path / "myenvs.py").write_text(POINT_ENV_MODULE)
    script = _console_script()
    assert script, "the shaped-es console script is not installed"
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    args = [script, "train", "--env", "myenvs:Point-v0", *TINY, "--out", "run"]
    args[args.index("inline")] = executor
    res = subprocess.run([*args, "--workers", "1"] if executor == "process" else args, cwd=tmp_path,
                         env=env, capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "run" / "checkpoints" / "latest.json").is_file()
    if executor == "process":
        return
    # the run used from another folder: its env's module is named, with what to do (this tree's code)
    own = {**env, "PYTHONPATH": str(SRC)}
    res = subprocess.run([sys.executable, "-m", "shaped_es", *args[1:-1], "own"], cwd=tmp_path, env=own,
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    (tmp_path / "elsewhere").mkdir()
    evaluate = [sys.executable, "-m", "shaped_es", "evaluate", str(tmp_path / "own"), "--episodes", "2"]
    res = subprocess.run(evaluate, cwd=tmp_path / "elsewhere", env={**env, "PYTHONPATH": str(SRC)},
                         capture_output=True, text=True, timeout=300)
    lines = res.stderr.strip().splitlines()
    assert res.returncode == 2 and len(lines) == 1, res.stderr
    assert "its module 'myenvs' cannot be imported from" in lines[0] and "PYTHONPATH" in lines[0]
    res = subprocess.run(evaluate, cwd=tmp_path / "elsewhere", env={**env, "PYTHONPATH": f"{SRC}:{tmp_path}"},
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0 and json.loads(res.stdout)["episodes"] == 2, res.stderr


def test_commands_in_order_and_where_their_handlers_live():
    """The subcommands, in the order ``--help`` lists them, each run by its module's handler (the parser is
    assembled in cli/commands.py from cli/results.py, cli/prune.py, cli/speed_commands.py,
    benchmark/cli_commands.py and cli/info.py)."""
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert list(sub.choices) == ["train", "resume", "evaluate", "benchmark", "suite", "report", "render", "prune",
                                 "config", "envs", "check-env", "speed", "bench"]
    where = {name: sp.get_default("fn").__module__ for name, sp in sub.choices.items() if sp.get_default("fn")}
    assert {k: where[k] for k in ("train", "resume", "evaluate", "report", "render", "prune")} == {
        "train": "shaped_es.cli.commands", "resume": "shaped_es.cli.commands", "evaluate": "shaped_es.cli.results",
        "report": "shaped_es.cli.results", "render": "shaped_es.cli.results", "prune": "shaped_es.cli.prune"}
    speed = next(a for a in sub.choices["speed"]._actions if isinstance(a, argparse._SubParsersAction))
    assert {n: sp.get_default("fn").__module__ for n, sp in speed.choices.items()} == {
        "env": "shaped_es.cli.speed_commands", "executors": "shaped_es.cli.speed_commands",
        "strategies": "shaped_es.speed.strategy_speed", "shaping": "shaped_es.cli.speed_commands"}


def _parsers(p: argparse.ArgumentParser, path=()):
    yield path, p
    for a in p._actions:
        if isinstance(a, argparse._SubParsersAction):
            for name, sp in a.choices.items():
                yield from _parsers(sp, (*path, name))


def test_every_option_of_every_command_explains_itself(capsys):
    """Every option of every (sub)command has a description and shows its default (the formatter's
    "(default: X)", or its own words for defaults taken from the config or the env); positionals are
    described; --method names what each method is."""
    seen, missing = 0, []
    for path, p in _parsers(build_parser()):
        fmt = p.formatter_class(prog="x")
        for a in p._actions:
            if isinstance(a, (argparse._HelpAction, argparse._VersionAction, argparse._SubParsersAction)):
                continue
            seen += 1
            text = fmt._format_action(a)
            if not (a.help or "").strip():
                missing.append((path, a.dest, "no help"))
            elif a.option_strings and not a.required and "default" not in text:
                missing.append((path, a.dest, "no default"))
            elif "(default: )" in text or "(default: None)" in text:
                missing.append((path, a.dest, "an empty default"))
    assert not missing, missing
    assert seen > 80
    train = _help(["train"])
    assert "(default: 50)" in train and "(default: vanilla)" in train and "(default: 32)" in train
    for method in ("vanilla", "guided", "cmaes", "shaped", "ppo"):
        assert f"{method}:" in train
    assert "(default: 15)" in _help(["evaluate"]) and "(default: 12345)" in _help(["evaluate"])
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0 and capsys.readouterr().out.strip() == f"shaped-es {__version__}"
    res = subprocess.run([sys.executable, "-m", "shaped_es", "--version"], capture_output=True, text=True)
    assert res.returncode == 0 and res.stdout.strip() == f"shaped-es {__version__}"
    res = subprocess.run([sys.executable, "-m", "shaped_es", "train", "--help"], capture_output=True, text=True)
    assert res.returncode == 0 and "--popsize" in res.stdout


def _help(path) -> str:
    return dict(_parsers(build_parser()))[tuple(path)].format_help()


def test_pairs_and_popsize(tmp_path, capsys):
    assert main(["train", "--env", "CartPole-v1", "--popsize", "7", "--out", str(tmp_path / "a")]) == 2
    assert "--popsize must be a positive even number" in _one_error_line(capsys)
    assert main(["train", "--env", "CartPole-v1", "--popsize", "8", "--pairs", "3", "--out",
                 str(tmp_path / "a")]) == 2
    assert "disagree" in _one_error_line(capsys) and not (tmp_path / "a").exists()
    i = TINY.index("--pairs")
    args = TINY[:i] + TINY[i + 2:]
    assert main(["train", "--env", "CartPole-v1", *args, "--popsize", "6", "--out", str(tmp_path / "b")]) == 0
    assert yaml.safe_load((tmp_path / "b" / "config.yaml").read_text())["es"]["pairs"] == 3
    assert main(["train", "--env", "CartPole-v1", *args, "--pairs", "3", "--out", str(tmp_path / "c")]) == 0
    assert yaml.safe_load((tmp_path / "c" / "config.yaml").read_text())["es"]["pairs"] == 3


def test_resume_below_the_generations_done_says_so(tmp_path, capsys):
    out = str(tmp_path / "r")
    assert main(["train", "--env", "CartPole-v1", *TINY, "--out", out]) == 0
    before = (tmp_path / "r" / "config.yaml").read_text()
    capsys.readouterr()
    assert main(["resume", out, "--generations", "1", "--quiet"]) == 2
    line = _one_error_line(capsys)
    assert "2 generations done" in line and "--generations 1" in line
    assert (tmp_path / "r" / "config.yaml").read_text() == before  # untouched
    assert main(["resume", out, "--generations", "3", "--quiet"]) == 0


def test_report_without_out_writes_a_folder_of_its_own(tmp_path, capsys, monkeypatch):
    run = str(tmp_path / "runs" / "r")
    assert main(["train", "--env", "CartPole-v1", *TINY, "--out", run]) == 0
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    capsys.readouterr()
    assert main(["report", run]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["report"] == "shaped-es-report/report.md"
    assert [p.name for p in work.iterdir()] == ["shaped-es-report"]  # nothing loose in the working folder
    assert {"report.md", "summary.json", "figures"} <= {p.name for p in (work / "shaped-es-report").iterdir()}


def test_train_stop_at_ends_the_run_as_finished(tmp_path, capsys):
    out = str(tmp_path / "r")
    args = [a if a != "2" else "4" for a in TINY[:4]] + TINY[4:]  # --generations 4
    assert main(["train", "--env", "CartPole-v1", *args, "--stop-at", "1", "--out", out]) == 0
    done = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert done["generations"] == 2  # CartPole scores >= 1: stopped after its first evaluated row
    assert yaml.safe_load((tmp_path / "r" / "config.yaml").read_text())["stop_at"] == 1.0
    assert main(["resume", out, "--quiet"]) == 0  # finished: resume has nothing to do
    assert json.loads(capsys.readouterr().out.strip().splitlines()[-1])["generations"] == 2
