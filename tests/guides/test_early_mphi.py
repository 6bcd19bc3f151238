"""shaping.early_mphi (guides/shaped_background.py): M_phi and the rival models train on generation 0's steps
before its clone, so generation 1 judges a candidate, where by default the run's own first one is generation
2's; generation 1 then trains nothing new, and a run resumed after generation 0 is the same run."""

from helpers import train

from shaped_es.config import build_config
from shaped_es.trainer import Trainer

BASE = {"env": "PointVel-v0", "method": "shaped", "executor": "inline", "es": {"pairs": 4},
        "rollout": {"episodes": 1, "test_episodes": 2},
        "shaping": {"mean_clone": {"probe_candidate": False}, "inverse_dynamics": {"frame": "world"}}}


def _cfg(generations: int, early: bool) -> dict:
    return BASE | {"generations": generations, "shaping": BASE["shaping"] | {"early_mphi": early}}


def _judged(store) -> list[bool]:
    return [r["candidate_accepted"] not in ("", None) for r in store.read_metrics()]


def test_generation_1_judges_a_candidate_and_a_resume_is_the_same_run(tmp_path):
    plain = train(tmp_path / "plain", _cfg(3, False))
    early = train(tmp_path / "early", _cfg(3, True))
    assert _judged(plain) == [False, False, True]
    assert _judged(early) == [False, True, True]
    rows = early.read_metrics()
    assert float(rows[0]["mphi_dataset_size"]) > 0  # generation 0's steps taken in at its end
    resumed = train(tmp_path / "resumed", _cfg(1, True))
    Trainer(build_config(_cfg(3, True)), resumed, progress=False).run()
    clocks = ("time", "wall", "cpu")
    for a, b in zip(rows, resumed.read_metrics(), strict=True):
        assert {k: v for k, v in a.items() if not any(c in k for c in clocks)} == \
            {k: v for k, v in b.items() if not any(c in k for c in clocks)}
