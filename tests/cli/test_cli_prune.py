"""``shaped-es prune``: one line per run and a total, a benchmark or suite folder stands for its runs,
``--dry-run`` deletes nothing, a folder that is no run is refused in one line before anything goes, and a
pruned run still evaluates, renders and reports while ``resume`` refuses it in one line, changing nothing.
What is deleted, and when a run is skipped: tests/rundir/test_prune.py."""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import subprocess
import sys

import pytest
import yaml

from helpers import SHAPED_TINY, SRC, train
from shaped_es.cli.commands import main


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return train(tmp_path_factory.mktemp("shaped") / "run", SHAPED_TINY).root


def snapshot(root):
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def _one_error_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("shaped-es: error: "), lines
    return lines[0]


def _unfinished(run):
    cfg = yaml.safe_load((run / "config.yaml").read_text())
    (run / "config.yaml").write_text(yaml.safe_dump({**cfg, "generations": 5}))
    return run


def test_a_pruned_run_evaluates_renders_and_reports_but_does_not_resume(finished, tmp_path, capsys):
    run = shutil.copytree(finished, tmp_path / "run")
    assert main(["prune", str(run)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"pruned {run}: ") and out[0].split(": ")[1].endswith(" MB freed (mphi_data/, "
                                                                                "mphi_data_rival/, mphi_data_servo/, "
                                                                                "mphi_data_shoot/, trajectories/, "
                                                                                "2 older checkpoints)")
    assert out[1].startswith("total: ") and out[1].endswith(" MB freed from 1 of 1 run") and len(out) == 2
    assert main(["evaluate", str(run), "--episodes", "2"]) == 0
    assert len(json.loads(capsys.readouterr().out)["episode_returns"]) == 2
    # render in a process of its own: UR5Reach-v0's frames load MuJoCo's renderer, after which this
    # process's first torch import (a later PPO test's) crashes in triton
    gif = subprocess.run([sys.executable, "-m", "shaped_es.cli.commands", "render", str(run), "--out",
                          str(tmp_path / "v.gif"), "--max-steps", "5"], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": str(SRC)}, timeout=300)
    assert gif.returncode == 0 and json.loads(gif.stdout)["frames"] == 6, gif.stderr
    assert main(["report", str(run), "--out", str(tmp_path / "rep" / "report.md")]) == 0
    capsys.readouterr()
    before = snapshot(run)
    for more in (["--generations", "6"], []):  # extended or not: what it would rebuild from is gone
        assert main(["resume", str(run), *more, "--quiet"]) == 2
        line = _one_error_line(capsys.readouterr().err)
        assert f"{run} was pruned on " in line and "cannot be resumed or extended" in line
        assert snapshot(run) == before


def test_dry_run_deletes_nothing(finished, tmp_path, capsys):
    run = shutil.copytree(finished, tmp_path / "run")
    before = snapshot(run)
    assert main(["prune", str(run), "--dry-run"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"would prune {run}: ") and "mphi_data/" in out[0] and "freed" not in out[0]
    assert out[1].endswith("would be freed from 1 of 1 run (--dry-run: nothing deleted)")
    assert snapshot(run) == before


def test_a_benchmark_and_a_suite_folder_prune_their_finished_runs(finished, tmp_path, capsys):
    bench = tmp_path / "bench"
    (bench / "runs").mkdir(parents=True)
    (bench / "benchmark.yaml").write_text("x: 1\n")
    shutil.copytree(finished, bench / "runs" / "shaped-s0")
    _unfinished(shutil.copytree(finished, bench / "runs" / "shaped-s1"))
    (bench / "runs" / "notes").mkdir()  # no run: not one of the benchmark's
    before = snapshot(bench / "runs" / "shaped-s1")
    assert main(["prune", str(bench)]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith(f"pruned {bench / 'runs' / 'shaped-s0'}: ")
    assert out[1] == (f"skipped {bench / 'runs' / 'shaped-s1'}: unfinished (3 of 5 generations done): resume it, "
                      f"or --force prunes it as it is (it then cannot be resumed)")
    assert out[2].endswith("freed from 1 of 2 runs") and len(out) == 3
    assert snapshot(bench / "runs" / "shaped-s1") == before
    suite = tmp_path / "suite"
    (suite / "suite.yaml").parent.mkdir()
    (suite / "suite.yaml").write_text("suite: x\n")
    shutil.copytree(bench, suite / "UR5Reach-v0")
    assert main(["prune", str(suite), "--force"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f"{suite / 'UR5Reach-v0' / 'runs' / 'shaped-s0'}: nothing freed; already pruned"
    assert out[1].startswith(f"pruned {suite / 'UR5Reach-v0' / 'runs' / 'shaped-s1'}: ")
    assert out[2].endswith("freed from 1 of 2 runs")


def test_a_folder_that_is_no_run_is_refused_before_anything_goes(finished, tmp_path, capsys):
    run = shutil.copytree(finished, tmp_path / "run")
    folder = tmp_path / "project"
    (folder / "mphi_data").mkdir(parents=True)
    (folder / "mphi_data" / "added_000001.npz").write_text("a user's file")
    before = snapshot(tmp_path)
    assert main(["prune", str(run), str(folder)]) == 2
    captured = capsys.readouterr()
    line = _one_error_line(captured.err)
    assert line == (f"shaped-es: error: {folder} is not a run directory (no config.yaml), nor a benchmark (runs/) "
                    f"or suite (suite.yaml) folder: nothing pruned")
    assert captured.out == "" and snapshot(tmp_path) == before
    assert main(["prune", str(tmp_path / "absent")]) == 2
    assert "does not exist: nothing pruned" in _one_error_line(capsys.readouterr().err)
