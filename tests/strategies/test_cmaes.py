"""CMA-ES's set_mean (the shaped method's candidate over CMA-ES) and its exact replay."""

import numpy as np
import pytest


def test_set_mean_jumps_and_the_replay_repeats_it():
    """An accepted candidate (shaped_cmaes) moves CMA's mean; a checkpoint's replay repeats the jump."""
    from helpers import npz_round_trip
    from shaped_es.strategies.cmaes import CMAES

    a = CMAES(np.zeros(4), 0.1, pairs=3, seed=0)
    for g in range(5):
        X = a.ask()
        a.tell(-np.sum(X ** 2, 1))
        if g == 2:
            a.set_mean(np.ones(4))
            np.testing.assert_array_equal(a.mean, np.ones(4))
    b = CMAES(np.zeros(4), 0.1, pairs=3, seed=0)
    b.load_state_dict(npz_round_trip(a.state_dict()))
    np.testing.assert_array_equal(a.mean, b.mean)
    np.testing.assert_array_equal(a.ask(), b.ask())
    with pytest.raises(RuntimeError, match="between ask"):
        a.set_mean(np.zeros(4))


def _run_with_jumps(a, jump_at=(1, 3)):
    for g in range(5):
        X = a.ask()
        a.tell(-np.sum((X - 2.0) ** 2, 1))
        if g in jump_at:
            a.set_mean(a.mean + 0.5)
    return a


def test_a_jump_zeroes_the_evolution_paths_so_the_step_size_does_not_read_it_as_a_path():
    from shaped_es.strategies.cmaes import CMAES

    a = CMAES(np.zeros(4), 0.1, pairs=3, seed=0)
    for _ in range(3):
        X = a.ask()
        a.tell(-np.sum((X - 2.0) ** 2, 1))  # a steady climb: the paths are long
    assert np.abs(a._es.adapt_sigma.ps).sum() > 0 and np.abs(a._es.pc).sum() > 0
    a.set_mean(a.mean + 1.0)
    assert not a._es.adapt_sigma.ps.any() and not a._es.pc.any()


def test_a_checkpoint_from_before_the_path_reset_replays_without_it():
    """A shaped_cmaes run checkpointed by an older version (no ``jump_resets_paths``) resumes as it ran."""
    from helpers import npz_round_trip
    from shaped_es.strategies.cmaes import CMAES

    old = CMAES(np.zeros(4), 0.1, pairs=3, seed=0)
    old.jump_resets_paths = False
    _run_with_jumps(old)
    state = old.state_dict()
    del state["jump_resets_paths"]
    b = CMAES(np.zeros(4), 0.1, pairs=3, seed=0)
    b.load_state_dict(npz_round_trip(state))  # raises if the replay did not reproduce the saved mean
    assert b.jump_resets_paths is False
    np.testing.assert_array_equal(old.ask(), b.ask())
    new = _run_with_jumps(CMAES(np.zeros(4), 0.1, pairs=3, seed=0))
    assert not np.array_equal(new.mean, old.mean)  # the reset changes the run
    c = CMAES(np.zeros(4), 0.1, pairs=3, seed=0)
    c.load_state_dict(npz_round_trip(new.state_dict()))
    assert c.jump_resets_paths is True
    np.testing.assert_array_equal(new.ask(), c.ask())


def test_search_scale_is_the_rms_of_pycmas_adapted_standard_deviations():
    """The shaped method's clone noise is in units of search_scale(): CMA-ES's adapted per-coordinate steps (their
    root mean square), not its initial sigma; Vanilla-ES's and Guided ES's sigma."""
    from shaped_es.strategies import make_strategy

    es = make_strategy("cmaes", np.zeros(6), sigma=0.3, popsize=8, seed=1, maximize=False)
    assert es.search_scale() == pytest.approx(0.3, rel=1e-3)
    for _ in range(15):  # a sphere: the step shrinks
        X = es.ask()
        es.tell(np.sum(X ** 2, axis=1))
    assert es.search_scale() == pytest.approx(np.sqrt(np.mean(np.square(es._es.stds))))
    assert es.search_scale() < 0.2
    for name in ("vanilla", "guided"):
        assert make_strategy(name, np.zeros(6), sigma=0.3, popsize=8).search_scale() == 0.3
