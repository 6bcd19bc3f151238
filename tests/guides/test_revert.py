"""The candidate mechanism's ``revert_margin``: a jump the next population (sampled around it) disproves is
undone, on a stub host; the check itself; the state round-trip; the back-off counts an undone jump as lost."""

import numpy as np
import pytest

from shaped_es.guides.label_budget import LabelBudget
from shaped_es.guides.mechanisms import candidate as cand_mod
from shaped_es.guides.mechanisms.candidate import MeanCandidate, population_fell
from shaped_es.shaping.settings import MeanCloneConfig
from shaped_es.strategies import GuidedES


class _Labels:
    ready = True


class _Host:
    def __init__(self, n, margin=1.0, paired=0.0, episodes=1):
        self.mean_clone_cfg = MeanCloneConfig(accept="mean", scales=(1.0,), extra_episodes=0, keep_step=False,
                                              revert_margin=margin, revert_paired=paired)
        self.labels = _Labels()
        self.rivals = []
        self.spec = type("S", (), {"num_params": n})()
        self.cfg = type("C", (), {"rollout": type("R", (), {"episodes": episodes})()})()  # common episodes

    def dagger_rows(self, generation, labels=None):  # one recorded row: the clones (mocked) run
        return type("Rows", (), {"lengths": lambda self: np.ones(1, np.int64)})()


def test_population_fell_needs_the_margin():
    before = (10.0, 4.0, 16)  # mean, variance, size: a standard error of 0.5 alone
    assert population_fell(np.full(16, 8.0), before, 1.0)  # variance 0: se 0.5, 2 below
    assert not population_fell(np.full(16, 9.8), before, 1.0)
    assert population_fell(np.full(16, 9.4), before, 1.0) and not population_fell(np.full(16, 9.4), before, 2.0)
    assert not population_fell(np.full(16, 0.0), (10.0, 0.0, 0), 1.0)  # nothing to compare with


def _generation(es, mech, g, fitness, extra_returns):
    es.ask()
    old = np.array(es.mean)
    es.tell(np.asarray(fitness, float))
    return mech.after_tell(g, None, np.asarray(fitness, float), np.asarray(extra_returns, float), [], old, es,
                           None)


@pytest.mark.parametrize("next_population,reverted", [(-100.0, True), (0.0, False)])
def test_a_jump_the_next_population_disproves_is_undone(monkeypatch, next_population, reverted):
    n, P = 4, 8
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    mech = MeanCandidate(_Host(n))
    assert "jump_reverted" in mech.metric_keys and "jump_reverted" not in MeanCandidate(_Host(n, 0.0)).metric_keys
    d = np.ones(n)
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, labels=None, key=0, rows=None: (mu + d, {"x": 1}))
    spread = np.linspace(-1, 1, P)  # (P,) the populations' returns around their means
    _generation(es, mech, 0, spread, np.zeros((0, 1)))
    out = _generation(es, mech, 1, spread, [[5.0], [1.0]])  # the candidate beats the mean: a jump
    assert out["candidate_accepted"] == 1 and out["jump_reverted"] == 0
    undo = mech.undo.copy()  # where the ES step alone took the mean
    assert not np.allclose(undo, es.mean)
    fresh = MeanCandidate(_Host(n))  # the state round-trips with the pending undo
    fresh.load_state_dict(mech.state_dict())
    np.testing.assert_array_equal(fresh.undo, undo)
    assert fresh.prev_pop == mech.prev_pop
    out = _generation(es, mech, 2, next_population + spread, [[5.0], [1.0]])  # its candidate wins again
    assert out["jump_reverted"] == int(reverted)
    assert out["candidate_accepted"] == int(not reverted)  # a winner cloned around a disproved jump is not taken
    if reverted:
        np.testing.assert_allclose(es.mean, undo)
        assert mech.undo is None
    else:
        assert mech.undo is not None  # this generation's jump is the next one's to judge


@pytest.mark.parametrize("undo_returns,reverted", [([9.0, 8.0, 9.5], True), ([4.0, 6.0, 5.0], False)])
def test_a_jump_the_es_steps_own_mean_beats_is_undone(monkeypatch, undo_returns, reverted):
    """revert_paired: after a jump, the mean the ES step alone gave runs as the row before the mean, on the same
    episodes; it wins the paired test against the jumped mean (returns 5 on each episode) only when it is
    clearly better."""
    n, P = 4, 8
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    mech = MeanCandidate(_Host(n, margin=0.0, paired=1.0, episodes=3))
    assert "jump_reverted" in mech.metric_keys
    d = np.ones(n)
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, labels=None, key=0, rows=None: (mu + d, {"x": 1}))
    spread = np.linspace(-1, 1, P)
    _generation(es, mech, 0, spread, np.zeros((0, 3)))
    assert mech.extras.shape == (2, n)  # the candidate, the mean: no jump yet, no undo row
    out = _generation(es, mech, 1, spread, [[5.0, 5.0, 5.0], [1.0, 1.0, 1.0]])  # a jump
    assert out["candidate_accepted"] == 1 and out["jump_reverted"] == 0
    undo = mech.undo.copy()
    assert mech.extras.shape == (3, n) and mech.undo_row == 1  # candidate, undo, the (jumped) mean
    np.testing.assert_allclose(mech.extras[1], undo.astype(np.float32))
    np.testing.assert_allclose(mech.extras[2], np.asarray(es.mean, np.float32))
    fresh = MeanCandidate(_Host(n, margin=0.0, paired=1.0, episodes=3))  # the undo row round-trips
    fresh.load_state_dict(mech.state_dict())
    assert fresh.undo_row == 1 and fresh.extras.shape == (3, n)
    # this generation's candidate beats the jumped mean too; the undo row is the ES step's mean's returns
    out = _generation(es, mech, 2, spread, [[7.0, 7.0, 7.0], undo_returns, [5.0, 5.0, 5.0]])
    assert out["jump_reverted"] == int(reverted)
    assert out["undo_gain"] == pytest.approx(np.mean(undo_returns) - 5.0)
    assert out["candidate_accepted"] == int(not reverted)
    if reverted:
        np.testing.assert_allclose(es.mean, undo)
    assert out["candidate_return"] == 7.0  # the candidate row is read as before the undo row
    assert mech.undo_row == int(not reverted)  # a new jump brings a new undo row


def test_an_undone_jump_counts_as_lost_for_the_back_off():
    b = LabelBudget(patience=3, max_sleep=8)
    b.judge(False, -1.0)
    b.judge(True, 2.0)  # resets the streak of 1
    assert b.losses == 0
    assert b.judge(False, -1.0, reverted=True)  # the jump undone (the streak of 1 is back, + 1) and this one lost
    assert not b.awake
