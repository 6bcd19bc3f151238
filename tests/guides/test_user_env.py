"""A user's env that meets only the two-key waypoint contract and never pays a positive reward
(examples/reacher_waypoints.py: Gymnasium's MuJoCo Reacher-v5 plus a wrapper) gets shaping with the
default settings: M_phi trains from the first generation and the mechanism's clone is evaluated."""

import sys
from pathlib import Path

import pytest

from helpers import train

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture
def reacher(monkeypatch):
    pytest.importorskip("imageio")  # Gymnasium's MuJoCo envs import it (the test extra brings it)
    monkeypatch.syspath_prepend(str(EXAMPLES))
    yield "reacher_waypoints:ReacherWaypoints-v0"
    sys.modules.pop("reacher_waypoints", None)


def test_shaping_runs_by_default_where_rewards_are_never_positive(tmp_path, reacher, monkeypatch):
    monkeypatch.chdir(tmp_path)  # MuJoCo logs Reacher-v5's model warnings to ./MUJOCO_LOG.TXT
    cfg = {"env": reacher, "method": "shaped", "executor": "inline", "generations": 3, "seed": 0,
           "es": {"pairs": 4}, "policy": {"hidden": [8]}, "rollout": {"episodes": 1, "test_episodes": 2},
           "tensorboard": False}
    rows = train(tmp_path / "reacher", cfg).read_metrics()
    assert all(float(r["train_reward_max"]) < 0 for r in rows)  # never a positive return
    # generation 0 judges the label probe's candidate; from generation 1 on, M_phi trained on generation 0's data
    assert [r["shaping_active"] for r in rows] == ["1", "1", "1"] and rows[0]["candidate_accepted"] in ("0", "1")
    assert float(rows[-1]["mphi_dataset_size"]) > 0
