"""state_dict / load_state_dict: numpy-only, npz round trip, bitwise-exact continuation; CMA-ES RNG
isolation."""

import numpy as np
import pytest
from helpers import npz_round_trip

from shaped_es.strategies import CMAES, make_strategy

HYPER = {
    "vanilla": dict(sigma=0.1, lr=0.05, pairs=4, seed=7, optimizer="adam", weight_decay=0.01),
    "vanilla_sgd": dict(sigma=0.1, lr=0.05, pairs=4, seed=7, optimizer="sgd", momentum=0.9),
    "guided": dict(sigma=0.1, lr=0.05, alpha=0.4, pairs=4, seed=7, optimizer="adam"),
    "cmaes": dict(sigma=0.3, pairs=4, seed=7, weight_decay=0.05, mu=25),
    "cmaes_diag": dict(sigma=0.3, pairs=4, seed=7, diagonal_above=5),
    # the float32 path of large policies, forced on the small test problem
    "vanilla_f32": dict(sigma=0.1, lr=0.05, pairs=4, seed=7, optimizer="adam", weight_decay=0.01,
                        float32_above=0),
    "guided_f32": dict(sigma=0.1, lr=0.05, alpha=0.4, pairs=4, seed=7, optimizer="adam", float32_above=0),
}


def _fitness(X):
    return -np.sum((X - 0.7) ** 2, axis=1) + np.sin(3 * X[:, 0])


def _generation(es, name, g):
    X = es.ask()
    es.tell(_fitness(X))
    if name.startswith("guided"):  # a surrogate for the next ask, as the trainer does after tell
        es.guide(np.random.default_rng(100 + g).standard_normal((2, es.num_params)))
    return X


def _build(name):
    return make_strategy(name.split("_")[0], np.linspace(-1, 1, 12), **HYPER[name])


@pytest.mark.parametrize("name", list(HYPER))
def test_resume_continues_bitwise(name):
    full = _build(name)
    X_full, m_full = [], []
    for g in range(12):
        X_full.append(_generation(full, name, g))
        m_full.append(full.mean.copy())

    first = _build(name)
    for g in range(5):
        _generation(first, name, g)
    state = first.state_dict()
    for k, v in state.items():
        assert isinstance(v, np.ndarray) and v.dtype != object, k
    loaded = npz_round_trip(state)

    resumed = _build(name)
    resumed.load_state_dict(loaded)
    assert resumed.generation == 5
    np.testing.assert_array_equal(resumed.mean, m_full[4])
    for g in range(5, 12):
        X = _generation(resumed, name, g)
        assert np.array_equal(X, X_full[g]), g
        assert np.array_equal(resumed.mean, m_full[g]), g
    assert resumed.best_fitness == full.best_fitness
    np.testing.assert_array_equal(resumed.best_params, full.best_params)


@pytest.mark.parametrize("name", ["vanilla", "guided", "cmaes"])
def test_load_rejects_mismatched_state(name):
    es = _build(name)
    _generation(es, name, 0)
    other = make_strategy(name, np.zeros(5), **HYPER[name])
    with pytest.raises((ValueError, KeyError)):
        other.load_state_dict(es.state_dict())


def test_cmaes_isolates_the_global_numpy_rng():
    np.random.seed(123)
    before = np.random.get_state()
    a = CMAES(np.ones(6), sigma=0.5, pairs=3, seed=1)
    Xa = [a.ask()]
    a.tell(_fitness(Xa[0]))
    after = np.random.get_state()
    assert before[0] == after[0] and np.array_equal(before[1], after[1]) and before[2:] == after[2:]

    b = CMAES(np.ones(6), sigma=0.5, pairs=3, seed=1)
    np.random.seed(999)
    np.random.standard_normal(1000)  # the caller's draws must not change ours
    Xb = b.ask()
    np.testing.assert_array_equal(Xb, Xa[0])
    c = CMAES(np.ones(6), sigma=0.5, pairs=3, seed=2)
    assert not np.array_equal(c.ask(), Xa[0])


def test_cmaes_ignores_surrogate_and_clips_mu_and_reports_pycma_mean():
    es = CMAES(np.zeros(4), sigma=0.2, pairs=2, seed=0, mu=25)
    assert es.mu == 2 and not es.diagonal
    X = es.ask()
    np.testing.assert_array_equal(es.ask(), X)  # idempotent until tell
    es.tell(_fitness(X), surrogate=np.ones((1, 4)))
    np.testing.assert_array_equal(es.mean, es._es.result.xfavorite)
    assert es.generation == 1 and es.best_fitness == _fitness(X).max()
