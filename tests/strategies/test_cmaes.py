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
