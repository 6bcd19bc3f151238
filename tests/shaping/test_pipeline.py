"""The shaped method end to end on UR5Reach-v0 (tiny budgets): alpha=1 is Vanilla-ES, resume is exact."""

import numpy as np
import pytest

from shaped_es.config import ConfigError, build_config
from shaped_es.store import RunStore
from shaped_es.trainer import TIME_COLUMNS, Trainer

TINY = {
    "env": "UR5Reach-v0",
    "executor": "inline",
    "generations": 4,
    "seed": 1,
    "es": {"pairs": 6},
    "policy": {"hidden": [8]},
    "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40},
    "shaping": {"inverse_dynamics": {"steps_per_generation": 30, "min_return": -1e9},
                "cloning": {"steps": 5}, "history": 2},
    "tensorboard": False,
}


def _run(tmp_path, name, **over):
    cfg = build_config({**TINY, **over})
    store = RunStore(tmp_path / name)
    store.create(cfg)
    Trainer(cfg, store, progress=False).run()
    return store


def _rewards(rows):
    return [(r["train_reward_mean"], r["train_reward_max"], r["test_reward_mean"]) for r in rows]


def test_alpha_one_reduces_to_vanilla(tmp_path):
    es = {**TINY["es"], "alpha": 1.0}
    shaped = _run(tmp_path, "shaped", method="shaped", es=es).read_metrics()
    vanilla = _run(tmp_path, "vanilla", method="vanilla", es=es).read_metrics()
    assert _rewards(shaped) == _rewards(vanilla)
    # ... while the shaped machinery really ran
    assert float(shaped[-1]["mphi_iterations"]) > 0 and int(shaped[-1]["surrogate_rank"]) > 0
    assert float(shaped[-1]["clone_loss_after"]) < float(shaped[-1]["clone_loss_before"])


def test_shaped_changes_search_and_resumes_exactly(tmp_path):
    full = _run(tmp_path, "full", method="shaped")
    vanilla = _run(tmp_path, "van", method="vanilla")
    assert _rewards(full.read_metrics())[2:] != _rewards(vanilla.read_metrics())[2:]
    part = _run(tmp_path, "part", method="shaped", generations=2)
    cfg = build_config({**TINY, "method": "shaped", "generations": 4})
    Trainer(cfg, part, progress=False).run()
    strip = lambda rows: [{k: v for k, v in r.items() if k not in TIME_COLUMNS and not k.startswith("time_")}
                          for r in rows]
    assert strip(part.read_metrics()) == strip(full.read_metrics())
    gens = sorted(p.name for p in (full.root / "trajectories").iterdir())
    assert gens == ["gen_000002", "gen_000003"]  # only shards a (re-)run of a later generation reads


def test_trajectories_on_a_uri_root_give_the_same_run(tmp_path):
    local = _run(tmp_path, "local", method="shaped", generations=3)
    uri = f"file://{tmp_path / 'shared'}"
    remote = _run(tmp_path, "remote", method="shaped", generations=3,
                  shaping={**TINY["shaping"], "trajectory_root": uri})
    assert _rewards(remote.read_metrics()) == _rewards(local.read_metrics())
    assert not (remote.root / "trajectories").exists()
    assert sorted(p.name for p in (tmp_path / "shared").iterdir()) == ["gen_000001", "gen_000002"]


def test_shaped_needs_the_waypoint_contract(tmp_path):
    cfg = build_config({**TINY, "env": "CartPole-v1", "method": "shaped"})
    store = RunStore(tmp_path / "cp")
    store.create(cfg)
    with pytest.raises(ConfigError, match="info\\['position'\\]"):
        Trainer(cfg, store, progress=False)
