"""The candidate mechanism's ``check_episodes``: a winner and the mean run more episodes at once and the jump
needs the paired test again on every episode the winner was not picked on; a plateau's flat win is not
checked; the check's env steps are reported (and counted by the trainer)."""

import numpy as np
import pytest

from shaped_es.guides.mechanisms import candidate as cand_mod
from shaped_es.guides.mechanisms.candidate import CHECK_METRIC, MeanCandidate
from shaped_es.shaping.settings import MeanCloneConfig
from shaped_es.strategies import GuidedES

E, X, N = 2, 4, 6  # common episodes, extra episodes, check episodes


class _Labels:
    ready = True


class _Host:
    def __init__(self, n, check=N, **kw):
        self.mean_clone_cfg = MeanCloneConfig(scales=(1.0,), extra_episodes=X, check_episodes=check, **kw)
        self.labels = _Labels()
        self.rivals = []
        self.spec = type("S", (), {"num_params": n})()
        self.cfg = type("C", (), {"seed": 3, "env": "E-v0", "env_kwargs": {},
                                  "rollout": type("R", (), {"episodes": E, "max_steps": None})()})()

    def dagger_rows(self, generation, labels=None):
        return type("Rows", (), {"lengths": lambda self: np.ones(1, np.int64)})()


class _Result:
    def __init__(self, returns):
        self.returns = np.asarray(returns, float)  # (m, n)
        self.lengths = np.full(self.returns.shape, 10)  # 10 steps an episode


def _mech(monkeypatch, check_gain, calls, check=N, **kw):
    n = 3
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=4, seed=0)
    mech = MeanCandidate(_Host(n, check, **kw))
    monkeypatch.setattr(cand_mod, "clone_mean",
                        lambda host, g, mu, cfg, labels=None, key=0, rows=None: (mu + 1.0, {"x": 1}))

    def tasks(env, kwargs, spec, policies, seeds, workers, generation, **k):
        calls.append((policies.copy(), seeds.copy(), generation))
        return [policies]

    monkeypatch.setattr(cand_mod, "population_tasks", tasks)
    # the check's episodes: the winner's returns check_gain above the mean's, with a spread of 1
    spread = np.resize([1.0, -1.0], check)
    mapper = lambda fn, ts: [_Result([5.0 + check_gain + spread, 5.0 + spread])]  # noqa: E731
    return es, mech, mapper


def _generation(es, mech, g, fitness, extra_returns, mapper):
    es.ask()
    old = np.array(es.mean)
    es.tell(np.asarray(fitness, float))
    return mech.after_tell(g, None, np.asarray(fitness, float), np.asarray(extra_returns, float), [], old, es,
                           mapper)


# the candidate ahead of the mean on the common episodes and a little on the extra ones: a paired win on all six
WINNER = [[7.0, 7.0, 7.0, 5.0, 5.5, 4.5], [5.0] * (E + X)]


@pytest.mark.parametrize("check_gain,accepted", [(0.0, 0), (-2.0, 0), (2.0, 1)])
def test_a_winner_jumps_only_if_the_check_episodes_bear_it_out(monkeypatch, check_gain, accepted):
    calls = []
    es, mech, mapper = _mech(monkeypatch, check_gain, calls)
    fitness = np.linspace(-1, 1, 8)
    _generation(es, mech, 0, fitness, np.zeros((0, E)), mapper)  # clones: the candidate for generation 1
    cand, mean = mech.extras[0].copy(), mech.extras[-1].copy()
    out = _generation(es, mech, 1, fitness, WINNER, mapper)
    assert out["candidate_accepted"] == accepted
    assert out[CHECK_METRIC] == 2 * N * 10  # two policies, N episodes, 10 steps each
    (policies, seeds, g), = calls
    np.testing.assert_array_equal(policies, np.stack([cand, mean]))  # the winner and the mean
    assert g == 1 and seeds.shape == (2, N) and (seeds[0] == seeds[1]).all()  # common episodes
    # the episodes past the E + X the extras ran in the generation's common stream: none seen before
    first = cand_mod.seeding.episode_seeds(3, cand_mod.seeding.TRAIN, 1, np.zeros(1), E + X)[0]
    assert not set(seeds[0]) & set(first)


def test_a_loser_runs_no_check(monkeypatch):
    calls = []
    es, mech, mapper = _mech(monkeypatch, 2.0, calls)
    fitness = np.linspace(-1, 1, 8)
    _generation(es, mech, 0, fitness, np.zeros((0, E)), mapper)
    out = _generation(es, mech, 1, fitness, [[4.0] * (E + X), [5.0] * (E + X)], mapper)
    assert out["candidate_accepted"] == 0 and out[CHECK_METRIC] == 0 and not calls


def test_a_plateau_win_is_not_checked(monkeypatch):
    calls = []
    es, mech, mapper = _mech(monkeypatch, -2.0, calls)
    flat = np.zeros(8)  # every member returned the same: accept_flat's win stands as before
    _generation(es, mech, 0, flat, np.zeros((0, E)), mapper)
    out = _generation(es, mech, 1, flat, [[0, 0, 1.0, 0, 0, 0], [0.0] * (E + X)], mapper)
    assert out["candidate_accepted"] == 1 and not calls


def test_no_check_without_check_episodes(monkeypatch):
    calls = []
    es, mech, mapper = _mech(monkeypatch, -2.0, calls, check=0)
    assert CHECK_METRIC not in mech.metric_keys
    fitness = np.linspace(-1, 1, 8)
    _generation(es, mech, 0, fitness, np.zeros((0, E)), mapper)
    out = _generation(es, mech, 1, fitness, WINNER, mapper)
    assert out["candidate_accepted"] == 1 and CHECK_METRIC not in out and not calls


def test_check_episodes_rejects_negative():
    with pytest.raises(ValueError):
        MeanCloneConfig(check_episodes=-1)


def test_a_run_counts_the_check_episodes_in_its_env_steps(tmp_path, monkeypatch):
    """Every judged candidate passes the paired test here, so each judged generation runs a check; its
    steps are the row's ``check_env_steps`` and part of ``gen_env_steps`` (the trainer's rollouts + it)."""
    import shaped_es.trainer as trainer_mod
    from helpers import train
    from test_mechanisms import TINY

    own: dict[int, int] = {}  # generation -> env steps of the trainer's own rollouts
    checks: dict[int, int] = {}  # generation -> env steps of the checks
    real_task, real_tasks = trainer_mod.run_task, trainer_mod.run_tasks

    def count(into, t, r):
        into[t.generation] = into.get(t.generation, 0) + int(r.lengths.sum())
        return r

    monkeypatch.setattr(trainer_mod, "run_task", lambda t: count(own, t, real_task(t)))
    monkeypatch.setattr(trainer_mod, "run_tasks", lambda ts: [count(own, t, r) for t, r in zip(ts, real_tasks(ts))])
    monkeypatch.setattr(cand_mod, "run_task", lambda t: count(checks, t, real_task(t)))
    monkeypatch.setattr(cand_mod, "paired_win", lambda *a, **k: True)
    sh = {**TINY["shaping"], "labels": "controller",
          "mean_clone": {**TINY["shaping"]["mean_clone"], "check_episodes": 3, "probe_candidate": False}}
    rows = train(tmp_path / "run", {**TINY, "generations": 4, "shaping": sh}).read_metrics()
    checked = [r for r in rows if r.get(CHECK_METRIC) not in (None, "", "0")]
    assert checked  # the candidates from generation 1 on
    for r in rows:
        g = int(r["generation"])
        assert int(r[CHECK_METRIC] or 0) == checks.get(g, 0)
        assert int(r["gen_env_steps"]) == own[g] + checks.get(g, 0)
