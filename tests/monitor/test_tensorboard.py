"""TensorBoard events: tags grouped train/ test/ shaping/ time/ misc/, env steps as the global step
(read back with TensorBoard's own EventAccumulator)."""

import math
from types import SimpleNamespace

import pytest
from helpers import train
from tensorboard.backend.event_processing.event_accumulator import EventAccumulator

from shaped_es.config import build_config
from shaped_es.monitor.tensorboard import tb_tag
from shaped_es.trainer import Trainer


def _scalars(tb_dir) -> EventAccumulator:
    acc = EventAccumulator(str(tb_dir), size_guidance={"scalars": 0})
    acc.Reload()
    return acc


@pytest.mark.parametrize("column, tag", [
    ("train_reward_mean", "train/train_reward_mean"),
    ("test_reward_best_so_far", "test/test_reward_best_so_far"),
    ("test_env_steps", "test/test_env_steps"),
    ("mphi_train_loss", "shaping/mphi_train_loss"),
    ("clone_loss_after", "shaping/clone_loss_after"),
    ("label_std", "shaping/label_std"),
    ("surrogate_rank", "shaping/surrogate_rank"),
    ("shaping_active", "shaping/shaping_active"),
    ("own_ref_error", "shaping/own_ref_error"),
    ("wall_time_s", "time/wall_time_s"),
    ("clone_cpu_time_s", "time/clone_cpu_time_s"),
    ("time_mphi_s", "time/time_mphi_s"),
    ("generation", "misc/generation"),
    ("update_norm", "misc/update_norm"),
    ("env_steps", "misc/env_steps"),
])
def test_tag_groups(column, tag):
    assert tb_tag(column) == tag


def test_trainer_events_grouped_at_env_steps(tmp_path):
    base = {"env": "CartPole-v1", "method": "vanilla", "seed": 0, "executor": "inline",
            "es": {"pairs": 2}, "policy": {"hidden": [4]}, "tensorboard": True,
            "rollout": {"episodes": 1, "test_episodes": 1, "max_steps": 30}}
    store = train(tmp_path / "run", {**base, "generations": 2})
    Trainer(build_config({**base, "generations": 3}), store, progress=False).run()  # resumed

    metrics = store.read_metrics()
    env_steps = [int(r["env_steps"]) for r in metrics]
    assert len(env_steps) == 3 and env_steps == sorted(set(env_steps))
    acc = _scalars(store.root / "tb")
    tags = set(acc.Tags()["scalars"])
    for tag in ("train/train_reward_mean", "test/test_reward_mean", "time/wall_time_s",
                "time/rollout_time_s", "misc/generation", "misc/update_norm"):
        assert tag in tags, sorted(tags)
    assert all(t.split("/")[0] in {"train", "test", "shaping", "time", "misc"} for t in tags)
    assert {t for t in tags if "/" not in t} == set()

    events = acc.Scalars("train/train_reward_mean")
    assert [e.step for e in events] == env_steps  # once per generation, the resume included
    assert [e.value for e in events] == pytest.approx([float(r["train_reward_mean"]) for r in metrics])
    assert [e.value for e in acc.Scalars("misc/generation")] == [0, 1, 2]
    assert [e.step for e in acc.Scalars("test/test_reward_mean")] == env_steps


@pytest.mark.parametrize("owner", ["trainer", "ppo"])
def test_shaping_row_logged_by_trainer(tmp_path, owner):
    if owner == "ppo":  # PPO runs log the same way
        from shaped_es.baselines.ppo import PPORun as cls
    else:
        cls = Trainer
    fake = SimpleNamespace(cfg=SimpleNamespace(tensorboard=True), store=SimpleNamespace(root=tmp_path),
                           _tb=None)
    row = {"generation": 4, "env_steps": 1234, "train_reward_mean": 1.5, "test_reward_mean": None,
           "mphi_train_loss": 0.25, "clone_ref_error": 0.5, "label_std": 0.1, "surrogate_rank": 3,
           "shaping_active": True, "time_mphi_s": 0.01, "clone_cpu_time_s": 0.2, "update_norm": 0.3,
           "label_ref_error": math.nan}
    cls._log_tb(fake, row)
    fake._tb.close()
    acc = _scalars(tmp_path / "tb")
    tags = set(acc.Tags()["scalars"])
    assert tags == {"misc/generation", "misc/env_steps", "train/train_reward_mean",
                    "shaping/mphi_train_loss", "shaping/clone_ref_error", "shaping/label_std",
                    "shaping/surrogate_rank", "shaping/shaping_active", "time/time_mphi_s",
                    "time/clone_cpu_time_s", "misc/update_norm"}  # None and NaN skipped
    (e,) = acc.Scalars("shaping/mphi_train_loss")
    assert e.step == 1234 and e.value == pytest.approx(0.25)
    assert acc.Scalars("shaping/shaping_active")[0].value == 1.0
