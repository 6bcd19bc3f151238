"""The rival label variants (guides/rival.py: another frame's M_phi, the forward model's servo, the shooting
labels): when a run
has them, that their clones are more candidates judged like the first, that a run resumes exactly with
them (and from a checkpoint of the single-rival format), that both placements agree, and that the jump goes
to a rival's row when that row wins (a stub host)."""

import numpy as np
import pytest

from helpers import new_run, run_until_crash, strip_time, train
from shaped_es.config import RunConfig
from shaped_es.guides.mechanisms.candidate import MeanCandidate
from shaped_es.guides.rival import (FRAME, HOLD_NAME, SERVO, SHOOT, SHOOT_HOLD, names, owned, rival_frame, rivals,
                                    servo_on, shoot_on)
from shaped_es.shaping.member_rows import MemberRows
from shaped_es.shaping.settings import InverseDynamicsConfig
from shaped_es.shaping.settings import MeanCloneConfig
from shaped_es.strategies import GuidedES
from shaped_es.trainer import Trainer

from test_mechanisms import TINY, _shaping  # noqa: E402 - the same tiny UR5Reach-v0 run


def _rival(frame="waypoint", mp=None, servo=True, shoot=True, **over):
    mp = {**TINY["shaping"]["inverse_dynamics"], "frame": "both", "rival_frame": frame, "rival_servo": servo,
          "rival_shoot": shoot, **(mp or {})}
    return {**TINY, "generations": 6, "shaping": _shaping(inverse_dynamics=mp, **over)}  # the rival trains from g1


@pytest.mark.parametrize("frame,over,dim,expected", [
    ("waypoint", {}, 3, "waypoint"), ("waypoint", {}, 1, None), ("none", {}, 3, None),
    ("waypoint", {"labels": "controller"}, 3, None), ("waypoint", {"mechanism": "pair"}, 3, None),
    ("world", {}, 2, "world"), ("both", {}, 2, None)])  # the run's own frame: no rival
def test_rival_only_with_mphi_candidates_another_frame_and_2d_waypoints(frame, over, dim, expected):
    cfg = RunConfig.model_validate(_rival(frame, **over))
    assert rival_frame(cfg, "both", dim) == expected
    assert servo_on(cfg) == ("labels" not in over and "mechanism" not in over)  # in any dimension
    assert not servo_on(RunConfig.model_validate(_rival(frame, servo=False, **over)))
    assert shoot_on(cfg) == ("labels" not in over and "mechanism" not in over)
    assert not shoot_on(RunConfig.model_validate(_rival(frame, shoot=False, **over)))


def test_the_probe_can_drop_the_shooting_rival(tmp_path):
    cfg = RunConfig.model_validate(_rival())
    kept = [r.variant for r in rivals(cfg, "both", 5, 3, 5, InverseDynamicsConfig(), tmp_path)]
    assert kept == [FRAME, SERVO, SHOOT]
    assert kept == [r.variant for r in rivals(cfg, "both", 5, 3, 5, InverseDynamicsConfig(), tmp_path, True)]
    assert [r.variant for r in rivals(cfg, "both", 5, 3, 5, InverseDynamicsConfig(), tmp_path, False)] == [
        FRAME, SERVO]


def test_the_shooting_rival_predicts_in_the_frame_the_probe_chose_unless_one_is_configured(tmp_path):
    cfg = RunConfig.model_validate(_rival())
    shooter = lambda c, **kw: next(r for r in rivals(c, "both", 5, 3, 5, InverseDynamicsConfig(), tmp_path, **kw)  # noqa: E731
                                   if r.variant == SHOOT)
    assert shooter(cfg).track.mphi.frame == "world"  # not probed: auto is the world frame
    r = shooter(cfg, shoot_frame="waypoint")
    assert r.track.mphi.frame == "waypoint" and names([r]) == ["shooting (4 steps, waypoint frame)"]
    fixed = RunConfig.model_validate(_rival(mp={"shoot_frame": "world"}))
    assert shooter(fixed, shoot_frame="waypoint").track.mphi.frame == "world"


def test_rival_candidate_is_judged_and_the_run_resumes_exactly(tmp_path, monkeypatch):
    from shaped_es.shaping.forward_shoot import ShootLabels

    monkeypatch.setattr(ShootLabels, "max_rows", 64)  # the shooting clone draws a subsample of the rows
    cut = []
    real = MemberRows.subsample
    monkeypatch.setattr(MemberRows, "subsample", lambda self, k, rng: cut.append(int(self.lengths()[0])) or
                        real(self, k, rng))
    full_store = train(tmp_path / "full", _rival())
    assert cut and max(cut) > 64
    full = full_store.read_metrics()
    judged = [r for r in full if r["candidate_accepted"] != ""]
    assert judged and all(r["candidate_rival"] in ("0", "1", "2", "3") for r in judged)
    assert all(r["rival_gain"] != "" and r["servo_gain"] != "" and r["shoot_gain"] != "" for r in judged)
    for d in ("mphi_data_rival", "mphi_data_servo", "mphi_data_shoot"):  # each its own data parts, for resume
        assert any((full_store.root / d).iterdir())
    plain = train(tmp_path / "plain", _rival("none", servo=False, shoot=False)).read_metrics()
    assert "candidate_rival" not in plain[0] and "servo_gain" not in plain[0] and "shoot_gain" not in plain[0]
    # the rivals' candidates run beside the first: more env steps once they are trained
    assert int(judged[-1]["gen_env_steps"]) > int(plain[int(judged[-1]["generation"])]["gen_env_steps"])
    cfg, store = new_run(tmp_path / "crashed", _rival())
    run_until_crash(monkeypatch, cfg, store, 3)
    monkeypatch.setattr(ShootLabels, "max_rows", 64)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_the_held_goal_rival_labels_on_the_shooting_rivals_model_and_owns_nothing(tmp_path):
    idc = InverseDynamicsConfig()
    hold = RunConfig.model_validate(_rival(mp={"rival_hold": True}))
    out = rivals(hold, "both", 5, 3, 5, idc, tmp_path)
    assert [r.variant for r in out] == [FRAME, SERVO, SHOOT, SHOOT_HOLD]
    shoot, held = out[2], out[3]
    assert held.track is shoot.track and held.labels is not shoot.labels  # one model, two label sources
    assert held.labels.hold and not shoot.labels.hold and held.labels.model is shoot.track.mphi
    assert held.shares and owned(out) == out[:3] and names(out)[3] == HOLD_NAME
    assert SHOOT_HOLD not in [r.variant for r in rivals(hold, "both", 5, 3, 5, idc, tmp_path, False)]  # dropped
    both = RunConfig.model_validate(_rival(mp={"rival_hold": True, "shoot_hold": True}))  # the labels hold already
    assert [r.variant for r in rivals(both, "both", 5, 3, 5, idc, tmp_path)] == [FRAME, SERVO, SHOOT]
    # idle (no clone, no candidate) where no row's waypoint is a goal held: its labels would be the shooting ones
    flat = MemberRows.from_lists([np.zeros((4, 5))], [np.zeros((4, 4))])  # (T, d + 1): the flag column last
    flagged = MemberRows.from_lists([np.zeros((4, 5))], [np.eye(4)])  # row 3 flagged
    assert held.idle(flat) and not held.idle(flagged) and not shoot.idle(flat)


def test_the_held_goal_candidates_episodes_are_not_recorded():
    """Its episodes would be every model's data: one more candidate changed what all labels learned from (a
    ReacherWay-v0 seed's rival gains parted from generation 3 on where it never won)."""
    host = _Host(4)
    host.rivals.append(type("R", (), {"ready": True, "labels": "held", "variant": SHOOT_HOLD, "records": False,
                                      "idle": lambda self, rows: False})())
    mech = MeanCandidate(host)
    mech.rivals, mech.extras = [FRAME, SHOOT_HOLD, SERVO], np.zeros((5, 4), np.float32)  # own, 3 rivals, the mean
    mask = mech.record_mask(6, 5)  # (6 + 5,): the population (every record_every-th), then the extras
    assert mask[6:].tolist() == [True, True, False, True, True]


def _flag_every_third(tr, before=None):
    return np.arange(len(tr)) % 3 == 0  # (T,) a goal held at every third row, whatever the body did


def test_the_held_goal_rival_is_judged_where_goals_are_held_and_the_run_resumes_exactly(tmp_path, monkeypatch):
    from shaped_es.shaping import forward_shoot

    cfg = _rival(mp={"rival_hold": True})
    monkeypatch.setattr(forward_shoot, "waypoint_held", _flag_every_third)
    full = train(tmp_path / "full", cfg).read_metrics()
    judged = [r for r in full if r["candidate_accepted"] != ""]
    assert judged and all(r["shoot_hold_gain"] != "" and r["shoot_gain"] != "" for r in judged[1:])
    assert judged[-1]["shoot_hold_gain"] != judged[-1]["shoot_gain"]  # another candidate, not a copy
    c, store = new_run(tmp_path / "crashed", cfg)
    run_until_crash(monkeypatch, c, store, 3)
    Trainer(c, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)
    # no goal held anywhere: no held-goal candidate, and the run is the run without the rival, cell for cell
    monkeypatch.setattr(forward_shoot, "waypoint_held", lambda tr, before=None: np.zeros(len(tr), bool))
    none = strip_time(train(tmp_path / "none", cfg).read_metrics())
    assert all(r["shoot_hold_gain"] == "" for r in none)
    plain = strip_time(train(tmp_path / "plain", _rival()).read_metrics())
    assert [{k: v for k, v in r.items() if k != "shoot_hold_gain"} for r in none] == plain


def test_master_and_worker_placement_give_the_same_rival_run(tmp_path):
    a, b = (strip_time(train(tmp_path / p, _rival(placement=p)).read_metrics()) for p in ("master", "workers"))
    assert a == b


# -- the jump to the rival's row, on a stub host -----------------------------------------------------------
class _Labels:
    ready = True


class _Host:
    def __init__(self, n):
        self.mean_clone_cfg = MeanCloneConfig(accept="mean", scales=(1.0,), extra_episodes=0, keep_step=False,
                                              revert_paired=0.0)  # the rows alone: no undo row after a jump
        self.labels = _Labels()
        self.rivals = [type("R", (), {"ready": True, "labels": f"rival labels {v}", "variant": v,
                                      "idle": lambda self, rows: False})()
                       for v in (FRAME, SERVO)]
        self.spec = type("S", (), {"num_params": n})()
        self.cfg = type("C", (), {"rollout": type("R", (), {"episodes": 1})()})()  # one common episode

    def dagger_rows(self, generation, labels=None):  # one recorded row: the clones (mocked) run
        return type("Rows", (), {"lengths": lambda self: np.ones(1, np.int64)})()


def test_the_rival_row_wins_and_becomes_the_mean(monkeypatch):
    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 4, 4
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    mech = MeanCandidate(_Host(n))
    assert {"candidate_rival", "rival_gain", "servo_gain"} <= set(mech.metric_keys)
    d_main, d_rival, d_servo = np.ones(n), -2.0 * np.ones(n), 3.0 * np.ones(n)
    d = {None: d_main, "rival labels 1": d_rival, "rival labels 2": d_servo}
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, labels=None, key=0, rows=None: (
        mu + d[labels], {"label_std": 0.1}))
    es.ask()
    es.tell(np.arange(P, dtype=float))
    mech.after_tell(0, None, np.zeros(P), np.zeros((0, 1)), [], np.zeros(n), es, None)
    mu0 = np.array(es.mean)
    rows = mech.extra_members(1)  # (4, n): the candidate, the rival frame's, the servo's, the mean
    np.testing.assert_allclose(rows, np.stack([mu0 + d_main, mu0 + d_rival, mu0 + d_servo, mu0]), rtol=1e-6)
    es.ask()
    es.tell(np.arange(P, dtype=float))
    out = mech.after_tell(1, None, np.arange(P, dtype=float), np.array([[2.0], [5.0], [3.0], [1.0]]), [], mu0,
                          es, None)
    assert out["candidate_accepted"] == 1 and out["candidate_rival"] == FRAME
    assert out["rival_gain"] == 4.0 and out["servo_gain"] == 2.0
    np.testing.assert_allclose(es.mean, mu0 + d_rival, rtol=1e-6)
    # the state round-trips with the rivals' rows and learners
    fresh = MeanCandidate(_Host(n))
    fresh.load_state_dict(mech.state_dict())
    np.testing.assert_array_equal(fresh.extra_members(2), mech.extra_members(2))
    assert fresh.rival_learners.keys() == mech.rival_learners.keys() == {FRAME, SERVO}
    for v in (FRAME, SERVO):
        np.testing.assert_array_equal(fresh.rival_learners[v], mech.rival_learners[v])
    # the servo's row wins the next generation
    es.ask()
    es.tell(np.arange(P, dtype=float))
    mu1 = np.array(es.mean)
    out = mech.after_tell(2, None, np.arange(P, dtype=float), np.array([[2.0], [1.0], [9.0], [1.0]]), [],
                          mu1, es, None)
    assert out["candidate_accepted"] == 1 and out["candidate_rival"] == SERVO and out["servo_gain"] == 8.0


@pytest.mark.parametrize("pick_all", [False, True])
def test_pick_all_tests_the_candidate_best_over_every_episode(monkeypatch, pick_all):
    """The own clone is lucky on the common episode and loses the extra ones; the frame rival's wins them all: the
    default picks (and so tests, and rejects) the own clone; ``pick_all`` the rival's, which passes."""
    from dataclasses import replace

    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 4, 4
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    host = _Host(n)
    host.mean_clone_cfg = replace(host.mean_clone_cfg, pick_all=pick_all)
    mech = MeanCandidate(host)
    d = {None: np.ones(n), "rival labels 1": -2.0 * np.ones(n), "rival labels 2": 3.0 * np.ones(n)}
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, labels=None, key=0, rows=None: (
        mu + d[labels], {"label_std": 0.1}))
    es.ask()
    es.tell(np.arange(P, dtype=float))
    mech.after_tell(0, None, np.zeros(P), np.zeros((0, 1)), [], np.zeros(n), es, None)
    es.ask()
    es.tell(np.arange(P, dtype=float))
    # (4, 3): the common episode, then two extra ones; rows: own, frame, servo, the mean
    ret = np.array([[5.0, 0.0, 0.0], [3.0, 4.0, 4.0], [2.0, 1.0, 1.0], [1.0, 1.0, 1.0]])
    out = mech.after_tell(1, None, np.arange(P, dtype=float), ret, [], np.array(es.mean), es, None)
    assert out["candidate_rival"] == (FRAME if pick_all else 0)
    assert out["candidate_accepted"] == int(pick_all)


def test_a_checkpoint_of_the_single_rival_format_loads():
    """Before the servo, the state held a count of rival rows (0/1) and one ``rival_learner``."""
    n = 4
    mech = MeanCandidate(_Host(n))
    rows = np.arange(3 * n, dtype=np.float32).reshape(3, n)  # the candidate, the rival frame's, the mean
    mech.load_state_dict({"extras": rows, "pending": np.array(0), "learner": np.zeros(0), "jumped": np.array(0),
                          "rivals": np.array(1), "rival_learner": np.ones(n)})
    assert mech.rivals == [FRAME] and set(mech.rival_learners) == {FRAME}
    with pytest.raises(ValueError, match="rival"):  # a row of a variant this run does not have
        mech.load_state_dict({"extras": rows, "pending": np.array(0), "rival_rows": np.array([7])})


def test_the_clones_on_threads_give_the_run_they_give_one_after_another(tmp_path, monkeypatch):
    """guides.concurrent runs the mean's and the rivals' clones (and the label probe's) on threads; with one core
    they run in turn: the same metrics rows either way."""
    from shaped_es.guides import concurrent

    if concurrent.threads() < 2:
        pytest.skip("one core: the clones run in turn anyway")
    threaded = strip_time(train(tmp_path / "threads", _rival()).read_metrics())
    monkeypatch.setattr(concurrent, "usable_cores", lambda: 1)
    in_turn = strip_time(train(tmp_path / "in_turn", _rival()).read_metrics())
    assert concurrent._POOL is not None  # the first run used the threads
    assert threaded == in_turn and any(r.get("candidate_rival") not in (None, "") for r in threaded)
