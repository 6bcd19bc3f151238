"""The rival label variant (guides/rival.py): when a run has one, that its clone is a second candidate
judged like the first, that a run resumes exactly with it, that both placements agree, and that the
jump goes to the rival's row when that row wins (a stub host)."""

import numpy as np
import pytest

from helpers import new_run, run_until_crash, strip_time, train
from shaped_es.config import RunConfig
from shaped_es.guides.mechanisms.candidate import MeanCandidate
from shaped_es.guides.rival import rival_frame
from shaped_es.shaping.settings import MeanCloneConfig
from shaped_es.strategies import GuidedES
from shaped_es.trainer import Trainer

from test_mechanisms import TINY, _shaping  # noqa: E402 - the same tiny UR5Reach-v0 run


def _rival(frame="waypoint", mp=None, **over):
    mp = {**TINY["shaping"]["inverse_dynamics"], "frame": "both", "rival_frame": frame, **(mp or {})}
    return {**TINY, "generations": 6, "shaping": _shaping(inverse_dynamics=mp, **over)}  # the rival trains from g1


@pytest.mark.parametrize("frame,over,dim,expected", [
    ("waypoint", {}, 3, "waypoint"), ("waypoint", {}, 1, None), ("none", {}, 3, None),
    ("waypoint", {"labels": "controller"}, 3, None), ("waypoint", {"mechanism": "pair"}, 3, None),
    ("world", {}, 2, "world"), ("both", {}, 2, None)])  # the run's own frame: no rival
def test_rival_only_with_mphi_candidates_another_frame_and_2d_waypoints(frame, over, dim, expected):
    cfg = RunConfig.model_validate(_rival(frame, **over))
    assert rival_frame(cfg, "both", dim) == expected


def test_rival_candidate_is_judged_and_the_run_resumes_exactly(tmp_path, monkeypatch):
    full_store = train(tmp_path / "full", _rival())
    full = full_store.read_metrics()
    judged = [r for r in full if r["candidate_accepted"] != ""]
    assert judged and all(r["candidate_rival"] in ("0", "1") for r in judged)
    assert all(r["rival_gain"] != "" for r in judged)
    assert any((full_store.root / "mphi_data_rival").iterdir())  # its own data parts, for resume
    plain = train(tmp_path / "plain", _rival("none")).read_metrics()
    assert "candidate_rival" not in plain[0]
    # the rival's candidate runs beside the first: more env steps once both are trained
    assert int(judged[-1]["gen_env_steps"]) > int(plain[int(judged[-1]["generation"])]["gen_env_steps"])
    cfg, store = new_run(tmp_path / "crashed", _rival())
    run_until_crash(monkeypatch, cfg, store, 3)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_master_and_worker_placement_give_the_same_rival_run(tmp_path):
    a, b = (strip_time(train(tmp_path / p, _rival(placement=p)).read_metrics()) for p in ("master", "workers"))
    assert a == b


# -- the jump to the rival's row, on a stub host -----------------------------------------------------------
class _Labels:
    ready = True


class _Host:
    def __init__(self, n):
        self.mean_clone_cfg = MeanCloneConfig(accept="mean", scales=(1.0,), extra_episodes=0, keep_step=False)
        self.labels = _Labels()
        self.rival = type("R", (), {"ready": True, "labels": "rival labels"})()
        self.spec = type("S", (), {"num_params": n})()
        self.cfg = type("C", (), {"rollout": type("R", (), {"episodes": 1})()})()  # one common episode


def test_the_rival_row_wins_and_becomes_the_mean(monkeypatch):
    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 4, 4
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    mech = MeanCandidate(_Host(n))
    assert "candidate_rival" in mech.metric_keys
    d_main, d_rival = np.ones(n), -2.0 * np.ones(n)
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, labels=None, key=0: (
        mu + (d_rival if labels == "rival labels" else d_main), {"label_std": 0.1}))
    es.ask()
    es.tell(np.arange(P, dtype=float))
    mech.after_tell(0, None, np.zeros(P), np.zeros((0, 1)), [], np.zeros(n), es, None)
    mu0 = np.array(es.mean)
    rows = mech.extra_members(1)  # (3, n): the candidate, the rival's, the mean
    np.testing.assert_allclose(rows, np.stack([mu0 + d_main, mu0 + d_rival, mu0]), rtol=1e-6)
    es.ask()
    es.tell(np.arange(P, dtype=float))
    out = mech.after_tell(1, None, np.arange(P, dtype=float), np.array([[2.0], [5.0], [1.0]]), [], mu0, es, None)
    assert out["candidate_accepted"] == 1 and out["candidate_rival"] == 1 and out["rival_gain"] == 4.0
    np.testing.assert_allclose(es.mean, mu0 + d_rival, rtol=1e-6)
    # the state round-trips with the rival's row and learner
    fresh = MeanCandidate(_Host(n))
    fresh.load_state_dict(mech.state_dict())
    np.testing.assert_array_equal(fresh.extra_members(2), mech.extra_members(2))
    np.testing.assert_array_equal(fresh.rival_learner, mech.rival_learner)
