"""Tiny end-to-end runs on CartPole-v1: learning, executor independence, kill-and-resume."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from shaped_es.config import build_config
from shaped_es.store import RunStore
from shaped_es.trainer import TIME_COLUMNS, Trainer

TINY = {
    "env": "CartPole-v1",
    "generations": 6,
    "seed": 3,
    "es": {"pairs": 8, "sigma": 0.1, "lr": 0.05},
    "policy": {"hidden": [8]},
    "rollout": {"episodes": 2, "test_episodes": 3},
    "tensorboard": False,
}


def _train(tmp_path, name, **over):
    cfg = build_config({**TINY, **over})
    store = RunStore(tmp_path / name)
    store.create(cfg)
    Trainer(cfg, store, progress=False).run()
    return store.read_metrics()


def _strip(rows):
    return [{k: v for k, v in r.items() if k not in TIME_COLUMNS} for r in rows]


@pytest.mark.parametrize("method", ["vanilla", "guided", "cmaes"])
def test_tiny_train_improves(tmp_path, method):
    rows = _train(tmp_path, method, method=method, executor="inline", generations=8)
    assert len(rows) == 8
    first = float(rows[0]["train_reward_mean"])
    best_late = max(float(r["train_reward_mean"]) for r in rows[-3:])
    assert best_late > 1.5 * first, (first, best_late)
    assert (tmp_path / method / "checkpoints" / "latest.json").is_file()


def test_inline_equals_process(tmp_path):
    a = _train(tmp_path, "inline", executor="inline", method="guided")
    b = _train(tmp_path, "proc", executor="process", workers=2, method="guided")
    assert _strip(a) == _strip(b)


def test_overlapped_and_separate_evaluation_equal_blocking(tmp_path):
    blocking = _train(tmp_path, "blocking", executor="process", workers=2, eval_overlap=False)
    overlap = _train(tmp_path, "overlap", executor="process", workers=2)
    separate = _train(tmp_path, "separate", executor="process", workers=1, eval_workers=1)
    assert _strip(overlap) == _strip(blocking) == _strip(separate)
    assert all(r["test_reward_mean"] != "" for r in overlap)


class _Crash(Exception):
    pass


def _crash_and_resume(tmp_path, monkeypatch, crash_at: int, **over):
    """Run until ``step(crash_at)`` raises; returns (full run's rows, rows the crash left, rows after resume)."""
    full = _train(tmp_path, "full", **over)
    cfg = build_config({**TINY, **over})
    store = RunStore(tmp_path / "crashed")
    store.create(cfg)
    step = Trainer.step

    def crashing(self, g):
        if g == crash_at:
            raise _Crash
        return step(self, g)

    monkeypatch.setattr(Trainer, "step", crashing)
    with pytest.raises(_Crash):
        Trainer(cfg, store, progress=False).run()
    left = [int(r["generation"]) for r in store.read_metrics()]
    monkeypatch.setattr(Trainer, "step", step)
    Trainer(cfg, store, progress=False).run()
    return full, left, store.read_metrics()


def test_resume_resubmits_test_episodes_in_flight_at_the_checkpoint(tmp_path, monkeypatch):
    # the checkpoint after g=3 holds row 3, its test episodes still in flight; step 4 dies before them
    full, left, resumed = _crash_and_resume(tmp_path, monkeypatch, 4, executor="inline", generations=8,
                                            checkpoint_every=2)
    assert left == [0, 1, 2], left  # row 3 waited for its test episodes when the run died
    assert _strip(resumed) == _strip(full)


def test_resume_drops_rows_written_after_the_checkpoint(tmp_path, monkeypatch):
    # the checkpoint after g=2 held row 2 in flight; steps 3 and 4 wrote rows 2 and 3, then step 5 dies
    full, left, resumed = _crash_and_resume(tmp_path, monkeypatch, 5, executor="inline", generations=8,
                                            checkpoint_every=3)
    assert left == [0, 1, 2, 3]
    assert _strip(resumed) == _strip(full)


def _cli(*args, **kw):
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[1] / "src")}
    return subprocess.Popen([sys.executable, "-m", "shaped_es.cli", *args], env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, **kw)


def test_kill_and_resume_gives_identical_rows(tmp_path):
    cfg = tmp_path / "tiny.yaml"
    import yaml

    cfg.write_text(yaml.safe_dump({**TINY, "generations": 14, "executor": "inline"}))
    full = _cli("train", "--config", str(cfg), "--out", str(tmp_path / "full"), "--quiet")
    assert full.wait(timeout=300) == 0, full.stderr.read()

    run = tmp_path / "killed"
    p = _cli("train", "--config", str(cfg), "--out", str(run), "--quiet")
    deadline = time.time() + 120
    while time.time() < deadline:
        m = run / "metrics.csv"
        if m.is_file() and len(m.read_text().splitlines()) >= 5:  # header + >= 4 rows
            break
        time.sleep(0.02)
    p.send_signal(signal.SIGKILL)
    p.wait()
    n_before = len((run / "metrics.csv").read_text().splitlines()) - 1
    assert 0 < n_before < 14, "the kill must land mid-run"
    r = _cli("resume", str(run), "--quiet")
    assert r.wait(timeout=300) == 0, r.stderr.read()
    a = RunStore(tmp_path / "full").read_metrics()
    b = RunStore(run).read_metrics()
    assert len(b) == 14
    assert _strip(a) == _strip(b)


@pytest.mark.parametrize(
    "args, needle",
    [
        (["train", "--env", "NoSuchEnv-v0", "--out", "{tmp}/a"], "NoSuchEnv-v0"),
        (["train", "--env", "nomod_xyz:Foo-v0", "--out", "{tmp}/b"], "nomod_xyz"),
        (["train", "--config", "{tmp}/missing.yaml", "--out", "{tmp}/c"], "not found"),
        (["train", "--env", "CartPole-v1", "--set", "es.sigma=-2", "--out", "{tmp}/d"], "es.sigma"),
        (["train", "--env", "CartPole-v1", "--set", "nonsense", "--out", "{tmp}/e"], "KEY=VALUE"),
        (["train", "--env", "CartPole-v1", "--set", "es.colour=3", "--out", "{tmp}/f"], "es.colour"),
        (["resume", "{tmp}/nothing-here"], "not a run directory"),
        (["evaluate", "{tmp}/nothing-here"], "not a run directory"),
    ],
)
def test_cli_bad_input_one_line_exit_2(tmp_path, args, needle):
    p = _cli(*[a.format(tmp=tmp_path) for a in args])
    out, err = p.communicate(timeout=120)
    assert p.returncode == 2, err
    lines = [l for l in err.splitlines() if l.strip()]
    assert len(lines) == 1 and needle in lines[0] and lines[0].startswith("shaped-es: error:"), err
    assert not (tmp_path / "a" / "config.yaml").exists()


def test_cli_existing_run_refused_and_untouched(tmp_path):
    p = _cli("train", "--env", "CartPole-v1", "--generations", "1", "--executor", "inline",
             "--set", "es.pairs=2", "--set", "rollout.test_episodes=1", "--out", str(tmp_path / "r"),
             "--quiet")
    assert p.wait(timeout=120) == 0, p.stderr.read()
    before = (tmp_path / "r" / "metrics.csv").read_bytes()
    q = _cli("train", "--env", "CartPole-v1", "--out", str(tmp_path / "r"))
    _, err = q.communicate(timeout=60)
    assert q.returncode == 2 and "already holds a run" in err
    assert (tmp_path / "r" / "metrics.csv").read_bytes() == before
