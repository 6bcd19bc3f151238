"""``cli/results.py``: ``shaped-es evaluate``'s ``--executor`` and ``--workers`` (a new user's evaluate always
started a process pool)."""

from __future__ import annotations

import json

import pytest
from helpers import CARTPOLE_TINY, train

from shaped_es.cli.commands import build_parser, main


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return train(tmp_path_factory.mktemp("evaluate") / "run", {**CARTPOLE_TINY, "generations": 1}).root


def _evaluate(run, capsys, *flags):
    capsys.readouterr()
    assert main(["evaluate", str(run), "--episodes", "3", *flags]) == 0
    return json.loads(capsys.readouterr().out)


def test_evaluate_takes_train_s_executors_and_gives_the_same_returns_on_each(finished, capsys):
    sub = next(a for a in build_parser()._actions if a.dest == "command").choices
    opts, train_opts = ({a.dest: a for a in sub[c]._actions} for c in ("evaluate", "train"))
    assert opts["executor"].choices == train_opts["executor"].choices
    assert opts["executor"].default == "process" and opts["workers"].default is None  # train's defaults
    inline = _evaluate(finished, capsys, "--executor", "inline")
    default = _evaluate(finished, capsys)
    two = _evaluate(finished, capsys, "--executor", "process", "--workers", "2")
    assert inline["episode_returns"] == default["episode_returns"] == two["episode_returns"]
    assert len(inline["episode_returns"]) == 3


def test_evaluate_refuses_workers_below_one_in_one_line(finished, capsys):
    capsys.readouterr()
    assert main(["evaluate", str(finished), "--executor", "inline", "--workers", "0"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["shaped-es: error: --workers must be positive, got 0"], err
