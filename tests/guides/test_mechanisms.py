"""The label mechanisms (guides/mechanisms/) end to end on UR5Reach-v0 with tiny budgets: what they log,
that they resume exactly, and that both placements give the same run; the candidate's acceptance rule
on a stub host."""

import numpy as np
import pytest

from helpers import new_run, run_until_crash, strip_time, train
from shaped_es.guides.mechanisms.candidate import MeanCandidate
from shaped_es.shaping.settings import MeanCloneConfig
from shaped_es.strategies import GuidedES
from shaped_es.trainer import Trainer

TINY = {
    "env": "UR5Reach-v0",
    "executor": "inline",
    "method": "shaped",
    "generations": 4,
    "seed": 1,
    "es": {"pairs": 6},
    "policy": {"hidden": [8]},
    "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40},
    "shaping": {"inverse_dynamics": {"steps_per_generation": 30, "filter": "none"}, "history": 2,
                "mean_clone": {"steps": 10, "batch_size": 32, "record_every": 3}},
    "tensorboard": False,
}


def _shaping(**over):
    return {**TINY["shaping"], **over}


@pytest.mark.parametrize("mechanism,labels,option", [
    ("candidate", "controller", None), ("candidate", "mphi", None),
    ("candidate", "controller", "confirm"), ("candidate", "controller", "extra_episodes"),
    ("candidate", "controller", "paired"), ("candidate", "controller", "best"),
    ("candidate", "mphi", "warm_start"), ("candidate", "controller", "no_repeat"), ("pair", "controller", None)])
def test_mechanism_logs_its_columns_and_resumes_exactly(tmp_path, monkeypatch, mechanism, labels, option):
    opts = {} if option is None else {option: 2 if option == "extra_episodes" else True}
    if option == "paired":
        opts = {"accept": "paired", "extra_episodes": 3}
    if option == "no_repeat":
        opts = {"keep_step_repeat": False}
    if option == "best":  # the rule before the suite's defaults: beat every member on the common episodes
        opts = {"accept": "best", "extra_episodes": 0, "keep_step": False}
    sh = _shaping(mechanism=mechanism, labels=labels, mean_clone={**TINY["shaping"]["mean_clone"], **opts})
    full = train(tmp_path / "full", {**TINY, "shaping": sh}).read_metrics()
    assert full[-1]["shaping_active"] == "1"
    if "candidate" in mechanism:
        scored = [r for r in full if r["candidate_return"] != ""]
        assert scored and all(r["candidate_accepted"] in ("0", "1") for r in scored)
        for r in scored:  # the gain is the candidate's return over the mean's, on the same episodes
            if {**MeanCloneConfig().__dict__, **opts}["extra_episodes"] == 0:  # (else: over all both ran)
                assert float(r["candidate_gain"]) == pytest.approx(
                    float(r["candidate_return"]) - float(r["mean_return"]))
    if "pair" in mechanism:
        assert any(r["pair_return_diff"] != "" for r in full)
    assert ("mphi_iterations" in full[0]) == (labels == "mphi")  # M_phi exists only as the label source
    assert "surrogate_rank" not in full[0]  # the paper's columns belong to its mechanism
    # a crash at generation 3, then a new trainer resumes from the checkpoint after generation 2
    cfg, store = new_run(tmp_path / "crashed", {**TINY, "shaping": sh})
    run_until_crash(monkeypatch, cfg, store, 3)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_controller_candidates_are_accepted_and_make_the_car_drive(tmp_path):
    """CarNav-v0 with the pure-pursuit controller's labels: the mean's clone beats the mean within a few
    generations and becomes the mean (the default rule, ``paired``: an accepted candidate's return is above
    the mean's over the common and extra episodes);
    the car then drives (the population's best return climbs from below 0 to > 50 in 6 generations;
    seeds 0-3 all reach 100-190)."""
    car = {**TINY, "env": "CarNav-v0", "policy": {"hidden": [32, 32]}, "es": {"pairs": 8},
           "rollout": {"episodes": 2, "test_episodes": 2, "max_steps": 150},
           "shaping": _shaping(mechanism="candidate", labels="controller",
                               mean_clone={"steps": 100, "batch_size": 128, "record_every": 4}),
           "generations": 6}
    rows = train(tmp_path / "c", car).read_metrics()
    accepted = [r for r in rows if r["candidate_accepted"] == "1"]
    assert accepted
    assert all(float(r["candidate_gain"]) > 0 for r in accepted)
    assert float(rows[0]["train_reward_max"]) < 0 and float(rows[-1]["train_reward_max"]) > 50


def test_master_and_worker_placement_give_the_same_candidate_run(tmp_path):
    for labels in ("controller", "mphi"):
        runs = [train(tmp_path / f"{labels}_{p}", {**TINY, "shaping": _shaping(
            mechanism="candidate", labels=labels, placement=p)}).read_metrics() for p in ("master", "workers")]
        a, b = (strip_time(r) for r in runs)
        assert a == b, labels


def test_controller_labels_need_the_hook(tmp_path):
    from shaped_es.config import ConfigError

    cfg, store = new_run(tmp_path / "pend", {**TINY, "env": "CartPole-v1", "shaping": _shaping(
        labels="controller")})
    with pytest.raises(ConfigError):  # CartPole has neither the contract nor a controller
        Trainer(cfg, store, progress=False)


def test_reference_labels_need_a_reference_run(tmp_path):
    from shaped_es.config import ConfigError

    cfg, store = new_run(tmp_path / "r", {**TINY, "shaping": _shaping(labels="reference",
                                                                      mechanism="candidate")})
    with pytest.raises(ConfigError, match="reference_run"):
        Trainer(cfg, store, progress=False)


def test_reference_labels_are_the_reference_policys_actions(tmp_path):
    ref = train(tmp_path / "ref", {**TINY, "method": "vanilla"})
    sh = _shaping(labels="reference", reference_run=str(ref.root), mechanism="candidate")
    rows = train(tmp_path / "r", {**TINY, "shaping": sh}).read_metrics()
    assert rows[-1]["shaping_active"] == "1" and rows[-1]["mphi_fig5_test_loss"] != ""
    # the labels are the reference's actions, so their error against the reference is zero
    assert all(float(r["mphi_fig5_test_loss"]) == pytest.approx(0.0, abs=1e-6)
               for r in rows if r["mphi_fig5_test_loss"] != "")


# -- the candidate's rule, on a stub host ---------------------------------------------------------------
class _Labels:
    ready = True


class _Host:
    def __init__(self, n, accept, **cfg):
        # the rule alone: no extra episodes, the jump replaces the ES update, no undo row after a jump (unless a
        # test says otherwise)
        self.mean_clone_cfg = MeanCloneConfig(**{"accept": accept, "scales": (0.5, 1.0), "extra_episodes": 0,
                                                 "keep_step": False, "revert_paired": 0.0, **cfg})
        self.labels = _Labels()
        self.spec = type("S", (), {"num_params": n})()
        self.cfg = type("C", (), {"rollout": type("R", (), {"episodes": 1})()})()  # one common episode

    def dagger_rows(self, generation, labels=None):  # one recorded row: the clone (mocked) runs
        return type("Rows", (), {"lengths": lambda self: np.ones(1, np.int64)})()


def test_the_means_clone_is_fitted_under_noise_scaled_by_the_searchs_sigma(monkeypatch):
    """mean_clone.noise is a share of the search's step (the guide's search_sigma, its strategy's search_scale()
    after the tell): the clone's steps take their gradient at theta + noise * sigma * z."""
    from shaped_es.guides.mechanisms import mean_clone as mc_mod
    from shaped_es.shaping.cloning import CloneResult

    seen = []

    def fake(spec, theta, rows, labels, cfg, seeds, **kw):
        seen.append(cfg)
        return CloneResult(theta_star=np.asarray(theta), loss_before=np.zeros(1), loss_after=np.zeros(1),
                           samples=np.ones(1, np.int64), label_std=0.0, reference=None)

    monkeypatch.setattr(mc_mod, "clone_sampled", fake)
    host = _Host(3, "paired", noise=0.5)
    host.cfg = type("C", (), {"seed": 0, "es": type("E", (), {"sigma": 9.0})()})()  # not read: the strategy's is
    host.search_sigma = 0.04
    host.reference = None
    for noise, want in ((0.5, 0.02), (0.0, 0.0)):
        cfg = MeanCloneConfig(noise=noise, noise_from=0)
        mc_mod.clone_mean(host, 1, np.zeros(3), cfg, rows=host.dagger_rows(1), labels=object())
        assert seen[-1].noise == pytest.approx(want)
    with pytest.raises(ValueError, match="noise"):
        MeanCloneConfig(noise=-1.0)
    # noise_from: the clones made before that generation are plain, from it on noisy
    cfg = MeanCloneConfig(noise=0.5, noise_from=3)
    for generation, want in ((0, 0.0), (2, 0.0), (3, 0.02), (7, 0.02)):
        mc_mod.clone_mean(host, generation, np.zeros(3), cfg, rows=host.dagger_rows(1), labels=object())
        assert seen[-1].noise == pytest.approx(want), generation
    with pytest.raises(ValueError, match="noise_from"):
        MeanCloneConfig(noise_from=-1)


@pytest.mark.parametrize("accept", ["best", "mean", "mean+keep_step"])
def test_candidate_becomes_the_mean_only_when_selection_prefers_it(monkeypatch, accept):
    """keep_step: the accepted candidate c_g keeps the ES update: mu_{g+1} = c_g + (mu_{g+1} - mu_g)."""
    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 5, 4
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    keep = accept.endswith("+keep_step")
    mech = MeanCandidate(_Host(n, accept.removesuffix("+keep_step"), keep_step=keep))
    theta_star = np.arange(1.0, n + 1)
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, **kw: (mu + theta_star, {"label_std": 0.1}))
    es.ask()
    es.tell(np.array([1.0, 2.0, 3.0, 4.0]))
    mech.after_tell(0, None, np.zeros(P), np.zeros((0, 1)), [], np.zeros(n), es, None)
    mu0 = np.array(es.mean)
    np.testing.assert_allclose(mech.extra_members(1), np.stack([mu0 + 0.5 * theta_star, mu0 + theta_star, mu0]),
                               rtol=1e-6)
    fitness = np.array([1.0, 2.0, 3.0, 4.0])
    # candidates: 3.5 (scale 0.5), 2.5; the mean's own return 1.0
    X = es.ask()
    assert X.shape == (P, n)
    es.tell(fitness)
    es_mean = np.array(es.mean)
    out = mech.after_tell(1, None, fitness, np.array([[3.5], [2.5], [1.0]]), [], mu0, es, None)
    assert out["candidate_return"] == 3.5 and out["mean_return"] == 1.0 and out["candidate_gain"] == 2.5
    assert out["candidate_scale"] == 0.5
    if accept == "best":  # 3.5 does not beat the best member's 4.0: the ES update stands
        assert out["candidate_accepted"] == 0
        np.testing.assert_array_equal(np.array(es.mean), es_mean)
    else:  # 3.5 beats the mean's own 1.0: the candidate is the new mean (with keep_step, plus the ES update)
        assert out["candidate_accepted"] == 1
        step = es_mean - mu0 if keep else 0.0  # (n,) the ES update of generation 1
        assert not keep or np.abs(step).max() > 0
        np.testing.assert_allclose(es.mean, mu0 + 0.5 * theta_star + step, rtol=1e-6)


def test_confirm_jumps_only_to_a_winner_that_beats_the_mean_again(monkeypatch):
    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 3, 4
    host = _Host(n, "best")
    host.mean_clone_cfg = MeanCloneConfig(scales=(1.0,), confirm=True, accept="best", extra_episodes=0,
                                          keep_step=False)  # one candidate a generation
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    mech = MeanCandidate(host)
    step = np.ones(n)
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, **kw: (mu + step, {"label_std": 0.1}))
    es.ask(); es.tell(np.zeros(P))
    mech.after_tell(0, None, np.zeros(P), np.zeros((0, 1)), [], np.zeros(n), es, None)
    c0 = mech.extra_members(1)[0].copy()
    # generation 1: the candidate wins (5 > 4): not accepted yet, carried as the pending row
    es.ask(); es.tell(np.array([1.0, 2.0, 3.0, 4.0]))
    out = mech.after_tell(1, None, np.array([1.0, 2.0, 3.0, 4.0]), np.array([[5.0], [0.0]]), [], np.zeros(n), es,
                          None)
    assert out["candidate_accepted"] == 0 and mech.pending == 1
    X = mech.extra_members(2)
    assert X.shape == (3, n) and np.allclose(X[1], c0)  # new candidate, the pending winner, the mean
    # generation 2: the pending one beats the mean's return (3 > 2.5, though not the best member's 4):
    # the mean jumps to it
    es.ask(); es.tell(np.array([1.0, 2.0, 3.0, 4.0]))
    out = mech.after_tell(2, None, np.array([1.0, 2.0, 3.0, 4.0]), np.array([[0.0], [3.0], [2.5]]), [],
                          np.zeros(n), es, None)
    assert out["candidate_accepted"] == 1 and mech.pending == 0
    np.testing.assert_allclose(es.mean, c0, rtol=1e-6)


def test_extra_episodes_make_a_winner_beat_the_mean_where_nobody_was_chosen(monkeypatch):
    """extra_episodes: the candidate wins on the common episode (5 > 4) but is accepted only if it also
    beats the mean on the episodes the population did not run."""
    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 3, 4
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, **kw: (mu + 1.0, {"label_std": 0.1}))
    for extra, accepted in (([[5.0, 1.0], [5.0, 1.0], [0.0, 2.0]], 0), ([[5.0, 3.0], [5.0, 3.0], [0.0, 2.0]], 1)):
        host = _Host(n, "best", extra_episodes=1)
        es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
        mech = MeanCandidate(host)
        assert mech.extra_episodes == 1
        es.ask(); es.tell(np.zeros(P))
        mech.after_tell(0, None, np.zeros(P), np.zeros((0, 2)), [], np.zeros(n), es, None)
        es.ask(); es.tell(np.array([1.0, 2.0, 3.0, 4.0]))
        out = mech.after_tell(1, None, np.array([1.0, 2.0, 3.0, 4.0]), np.array(extra), [], np.zeros(n), es, None)
        assert out["candidate_accepted"] == accepted


@pytest.mark.parametrize("repeat", [True, False])
def test_keep_step_repeat_decides_the_step_of_a_jump_right_after_a_jump(monkeypatch, repeat):
    """Two accepted generations in a row: the first keeps the ES update; the second does too only with
    keep_step_repeat (off: it lands on the candidate itself); a third, after a rejected one, keeps it again."""
    from shaped_es.guides.mechanisms import candidate as cand_mod

    n, P = 3, 4
    monkeypatch.setattr(cand_mod, "clone_mean", lambda host, g, mu, cfg, **kw: (mu + 1.0, {"label_std": 0.1}))
    mech = MeanCandidate(_Host(n, "mean", scales=(1.0,), keep_step=True, keep_step_repeat=repeat))
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=P // 2, seed=0)
    es.ask(); es.tell(np.zeros(P))
    mech.after_tell(0, None, np.zeros(P), np.zeros((0, 1)), [], np.zeros(n), es, None)
    for g, (wins, stepped) in enumerate([(True, True), (True, repeat), (False, False), (True, True)], start=1):
        cand = mech.extra_members(g)[0].astype(np.float64)  # (n,) this generation's candidate
        old = np.array(es.mean)
        es.ask(); es.tell(np.array([1.0, 2.0, 3.0, 4.0]))
        update = np.array(es.mean) - old  # (n,) the ES update
        out = mech.after_tell(g, None, np.ones(P), np.array([[5.0 if wins else 0.0], [1.0]]), [], old, es, None)
        assert out["candidate_accepted"] == int(wins) and mech.jumped == wins
        want = (cand + update if stepped else cand) if wins else old + update
        np.testing.assert_allclose(es.mean, want, rtol=1e-5, atol=1e-6)
    assert int(mech.state_dict()["jumped"]) == 1
    assert np.any(es.opt.m != 0)  # reset_momentum off: the ES optimizer's momentum is kept across jumps
    mech.cfg = MeanCloneConfig(**{**mech.cfg.__dict__, "reset_momentum": True})
    es.ask(); es.tell(np.array([1.0, 2.0, 3.0, 4.0]))
    mech.after_tell(5, None, np.ones(P), np.array([[5.0], [1.0]]), [], np.array(es.mean), es, None)
    assert np.all(es.opt.m == 0) and np.any(es.opt.v != 0)  # on: the jump forgot it (Adam's scale kept)
    fresh = MeanCandidate(_Host(n, "mean", scales=(1.0,)))
    fresh.load_state_dict(mech.state_dict())
    assert fresh.jumped
    fresh.load_state_dict({k: v for k, v in mech.state_dict().items() if k != "jumped"})  # an older checkpoint
    assert not fresh.jumped


def test_babbling_policies_feed_m_phi_and_resume_exactly(tmp_path, monkeypatch):
    """inverse_dynamics.babble: random policies roll out beside the population in the first generations;
    their steps are M_phi's data (more rows than without), they change no ES step by their returns
    (same population returns in generation 0), and a resumed run draws the same babblers."""
    sh = _shaping(inverse_dynamics={**TINY["shaping"]["inverse_dynamics"], "babble": 3,
                                    "babble_generations": 4})
    base = train(tmp_path / "base", {**TINY, "shaping": _shaping(inverse_dynamics={
        **TINY["shaping"]["inverse_dynamics"], "babble": 0})}).read_metrics()
    full = train(tmp_path / "full", {**TINY, "shaping": sh}).read_metrics()
    assert full[0]["train_reward_mean"] == base[0]["train_reward_mean"]  # the population is the same
    assert int(full[0]["gen_env_steps"]) > int(base[0]["gen_env_steps"])  # ... the babblers ran beside it
    assert float(full[1]["mphi_dataset_size"]) > float(base[1]["mphi_dataset_size"])
    cfg, store = new_run(tmp_path / "crashed", {**TINY, "shaping": sh})
    run_until_crash(monkeypatch, cfg, store, 3)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_babbling_is_off_without_m_phi(tmp_path):
    """Babbling feeds M_phi: with the controller's labels (no M_phi) the run is the same without it."""
    sh = _shaping(labels="controller", inverse_dynamics={**TINY["shaping"]["inverse_dynamics"], "babble": 3,
                                                         "babble_generations": 1})
    ctrl = train(tmp_path / "ctrl", {**TINY, "generations": 2, "shaping": sh}).read_metrics()
    plain = train(tmp_path / "plain", {**TINY, "generations": 2, "shaping": _shaping(labels="controller")})
    assert strip_time(ctrl) == strip_time(plain.read_metrics())


def test_paired_win_needs_more_than_a_standard_error():
    from shaped_es.guides.mechanisms.candidate import paired_win

    mean = np.array([0.0, 0.0, 0.0, 0.0])
    assert paired_win(np.array([1.0, 1.2, 0.9, 1.1]), mean)  # a steady gain
    assert not paired_win(np.array([9.0, -3.0, -3.0, -2.0]), mean)  # one lucky episode
    assert not paired_win(np.array([-1.0, -1.0, -1.0, -1.0]), mean)


def test_a_sparse_rewards_one_success_wins_only_on_a_flat_population():
    """One success among n episodes (the rest tied at a sparse reward's floor) is x / n against a standard
    error of x / n: never significant. Where every member returned the same, a mean gain is enough."""
    from shaped_es.guides.mechanisms.candidate import flat_win, paired_win

    floor = np.full(6, -25.0)
    one = floor.copy()
    one[2] = 150.0
    assert not paired_win(one, floor)
    assert flat_win(np.full(8, -25.0), one, floor)
    assert not flat_win(np.array([-25.0] * 7 + [-24.0]), one, floor)  # the population has a signal
    crash = one.copy()
    crash[4] = -60.0  # one success, one crash: still a mean gain
    assert flat_win(np.full(8, -25.0), crash, floor)
    assert not flat_win(np.full(8, -25.0), floor, floor)  # no gain
    assert not flat_win(np.zeros(0), one, floor)


def test_shaped_cmaes_resumes_exactly(tmp_path, monkeypatch):
    """The candidate over CMA-ES (--method shaped_cmaes): the controller's candidates are judged, and a
    run crashed at generation 3 resumes to the uninterrupted run's rows."""
    cfg = {**TINY, "method": "shaped_cmaes", "shaping": _shaping(labels="controller")}
    full = train(tmp_path / "full", cfg).read_metrics()
    assert any(r["candidate_accepted"] in ("0", "1") for r in full)
    c, store = new_run(tmp_path / "crashed", cfg)
    run_until_crash(monkeypatch, c, store, 3)
    Trainer(c, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_babblers_run_the_population_episodes_and_judged_extras_run_more(tmp_path, monkeypatch):
    """extra_episodes is for the candidates and the mean, which are judged; the babblers (M_phi's data only)
    run the population's E episodes (with them, a babbling generation cost 3x their steps)."""
    import shaped_es.trainer as trainer_mod

    seen: list[tuple[int, np.ndarray, int]] = []  # (generation, members, episodes) of every training task
    real_task, real_tasks = trainer_mod.run_task, trainer_mod.run_tasks

    def spy(t):
        seen.append((t.generation, np.asarray(t.members), t.seeds.shape[1]))
        return real_task(t)

    def spy_all(ts):
        for t in ts:
            seen.append((t.generation, np.asarray(t.members), t.seeds.shape[1]))
        return real_tasks(ts)

    monkeypatch.setattr(trainer_mod, "run_task", spy)
    monkeypatch.setattr(trainer_mod, "run_tasks", spy_all)
    babble, x = 3, 4
    sh = _shaping(inverse_dynamics={**TINY["shaping"]["inverse_dynamics"], "babble": babble, "babble_generations": 3},
                  mean_clone={**TINY["shaping"]["mean_clone"], "extra_episodes": x})
    train(tmp_path / "run", {**TINY, "generations": 3, "shaping": sh})
    E, P = TINY["rollout"]["episodes"], 2 * TINY["es"]["pairs"]
    both = 0  # generations where candidates and babblers ran (the candidates from generation 2 here)
    for g in range(3):
        tasks = [(m, e) for gen, m, e in seen if gen == g and m.min() >= P]
        top = max(int(m.max()) for m, _ in tasks)
        babblers = [e for m, e in tasks if m.min() > top - babble]
        judged = [e for m, e in tasks if m.max() <= top - babble]
        assert babblers and set(babblers) == {E}
        assert set(judged) <= {E + x}
        both += bool(judged)
    assert both
