"""Weights & Biases logging (``--wandb``): every metrics row under the TensorBoard tags, against a small fake
of the ``wandb`` module (always) and the real package in offline mode (when it is installed: the
``[wandb]`` extra)."""

import sys
import types

import pytest

from helpers import CARTPOLE_TINY, new_run
from shaped_es.monitor.tensorboard import tb_tag
from shaped_es.trainer import Trainer

CFG = {**CARTPOLE_TINY, "executor": "inline", "generations": 3, "wandb": {"enabled": True, "mode": "offline"}}


class FakeRun:
    offline = True

    def __init__(self, **kw):
        self.kw, self.logged, self.metrics, self.finished = kw, [], [], False
        self.settings = types.SimpleNamespace(sync_dir=f"{kw['dir']}/wandb/offline-run-x")

    def define_metric(self, name, step_metric=None):
        self.metrics.append((name, step_metric))

    def log(self, data):
        self.logged.append(data)

    def finish(self):
        self.finished = True


@pytest.fixture
def fake_wandb(monkeypatch):
    runs = []

    def init(**kw):
        runs.append(FakeRun(**kw))
        return runs[-1]

    monkeypatch.setitem(sys.modules, "wandb", types.SimpleNamespace(init=init, Settings=lambda **kw: kw))
    return runs


def test_rows_go_to_wandb_under_the_tensorboard_tags(tmp_path, fake_wandb):
    cfg, store = new_run(tmp_path / "r", CFG)
    Trainer(cfg, store, progress=False).run()
    (run,) = fake_wandb
    rows = store.read_metrics()
    assert len(run.logged) == len(rows) == 3 and run.finished
    for row, data in zip(rows, run.logged):
        expected = {tb_tag(k): float(v) for k, v in row.items() if v != ""}
        assert data == pytest.approx(expected)
    assert set(run.logged[0]) >= {"train/train_reward_mean", "test/test_reward_mean", "time/wall_time_s",
                                  "misc/env_steps"}
    assert ("*", "misc/env_steps") in run.metrics  # env steps on every chart's x axis, as TensorBoard
    assert run.kw["mode"] == "offline" and run.kw["name"] == "r" and run.kw["config"]["seed"] == 3
    # resume continues the same W&B run
    cfg = cfg.model_copy(update={"generations": 4})
    Trainer(cfg, store, progress=False).run()
    assert fake_wandb[1].kw["id"] == run.kw["id"] == (store.root / "wandb_id").read_text().strip()
    assert fake_wandb[1].kw["resume"] == "allow" and len(fake_wandb[1].logged) == 1


def test_without_the_package_train_says_how_to_get_it(tmp_path, monkeypatch, capsys):
    import importlib.util

    from shaped_es.cli.commands import main

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "wandb" else real(name, *a))
    assert main(["train", "--env", "CartPole-v1", "--wandb", "--executor", "inline", "--quiet",
                 "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install 'shaped-es[wandb]'" in err[0] and not (tmp_path / "r").exists()


def test_the_real_package_offline(tmp_path, monkeypatch):
    pytest.importorskip("wandb")
    monkeypatch.setenv("WANDB_MODE", "offline")
    monkeypatch.setenv("WANDB_SILENT", "true")
    cfg, store = new_run(tmp_path / "r", {**CFG, "wandb": {"enabled": True}})
    Trainer(cfg, store, progress=False).run()
    run_id = (store.root / "wandb_id").read_text().strip()
    (offline,) = list((store.root / "wandb").glob(f"offline-run-*-{run_id}"))
    data = offline / f"run-{run_id}.wandb"
    assert data.stat().st_size > 0  # the rows, for a later `wandb sync`
