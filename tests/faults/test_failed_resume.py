"""A resume that fails changes nothing saved: each case damages a finished run (or makes its env fail in
the resumed first generation), resumes it to more generations in a real process, and expects exit 2,
one line, and every file of the run directory byte for byte as before (error.log aside). Before, the
metrics-header and ``figures/`` / ``tb/`` cases failed only after a generation ran: checkpoints were
pruned and ``latest.json`` re-pointed."""

from __future__ import annotations

import shutil

import pytest
from fault_run import one_error_line, replace_with_file, run_cli, snapshot, write_config

BASE = {"env": "fault_envs:Faulty-v0", "method": "vanilla", "executor": "inline", "generations": 3, "seed": 5,
        "es": {"pairs": 2}, "policy": {"hidden": [4]}, "rollout": {"episodes": 1, "test_episodes": 1},
        "checkpoint_every": 1, "tensorboard": True}


def cut_last_column(run, tmp):
    p = run / "metrics.csv"
    p.write_text("".join(",".join(ln.split(",")[:-1]) + "\r\n" for ln in p.read_text().splitlines()))


def env_fails(run, tmp):
    """The env raises from now on (its marker is gone), and the directory holds what recovery repairs:
    a row past the checkpoint, a stale latest.json."""
    (tmp / "marker").unlink()
    rows = (run / "metrics.csv").read_text().splitlines()
    (run / "metrics.csv").write_text("\r\n".join(rows + ["3" + rows[-1][rows[-1].index(","):]]) + "\r\n")
    (run / "checkpoints" / "latest.json").write_text('{"name": "gen_000002"}')


CASES = [
    ("metrics-last-column-cut", cut_last_column, "lacks the columns ['update_norm']"),
    ("figures-is-a-file", replace_with_file("figures"), "figures is not a folder"),
    ("tb-is-a-file", replace_with_file("tb"), "tb is not a folder"),
    ("env-fails-in-first-generation", env_fails, "RuntimeError: the simulator lost its connection"),
]


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("base")
    (tmp / "marker").write_text("0")  # present: the env behaves
    cfg = dict(BASE, env_kwargs={"fault": "raise_step", "marker": "marker"})  # in the working folder
    res = run_cli("train", "--config", write_config(tmp / "cfg.yaml", cfg), "--out", "run", "--quiet", cwd=tmp)
    assert res.returncode == 0, res.stderr
    return tmp


@pytest.mark.parametrize("damage, needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_failed_resume_changes_nothing(base, tmp_path, damage, needle):
    shutil.copytree(base, tmp_path / "b")
    run = tmp_path / "b" / "run"
    damage(run, tmp_path / "b")
    before = snapshot(run)
    res = run_cli("resume", run, "--generations", 5, "--quiet", cwd=tmp_path / "b")
    assert res.returncode == 2
    assert needle in one_error_line(res.stderr)
    assert snapshot(run) == before
