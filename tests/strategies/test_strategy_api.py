"""The strategies as evosax/EvoTorch users call them: ``popsize=``, ``maximize=False`` for losses, and
CMA-ES weight decay off by default in the Python API (the paper's 0.05 stays in the run config)."""

import numpy as np
import pytest

from shaped_es.config import build_config
from shaped_es.strategies import CMAES, GuidedES, VanillaES, make_strategy
from shaped_es.trainer import build_strategy

HYPER = {
    "vanilla": dict(sigma=0.1, lr=0.1, fitness_shaping="none", optimizer="sgd"),
    "vanilla_rank": dict(sigma=0.1, lr=0.02, fitness_shaping="rank", optimizer="adam"),
    "guided": dict(sigma=0.1, lr=0.02, alpha=0.5, optimizer="adam"),
    "cmaes": dict(sigma=0.5, mu=25),
}
GENS = {"vanilla": 200, "vanilla_rank": 400, "guided": 400, "cmaes": 200}
TOL = {"vanilla": 1e-4, "vanilla_rank": 0.05, "guided": 0.05, "cmaes": 1e-6}


def _sphere(X):
    return np.sum(np.asarray(X, dtype=np.float64) ** 2, axis=1)  # a loss: smaller is better


def _run(es, objective, gens, guided):
    for _ in range(gens):
        old = es.mean.copy()
        es.tell(objective(es.ask()))
        if guided:
            es.guide(es.mean - old)
    return es


@pytest.mark.parametrize("name", list(HYPER))
def test_sphere_minimized_with_maximize_false(name):
    kind = name.split("_")[0]
    es = make_strategy(kind, np.full(10, 1.5), popsize=16, seed=0, maximize=False, **HYPER[name])
    _run(es, _sphere, GENS[name], kind == "guided")
    assert np.linalg.norm(es.mean) < TOL[name], np.linalg.norm(es.mean)
    assert es.best_fitness == pytest.approx(_sphere(es.best_params[None])[0])  # the lowest loss, as told
    assert es.best_fitness < _sphere(np.full((1, 10), 1.5))[0]

    # the same run as maximizing the negated loss, bit for bit (tell negates internally)
    ref = make_strategy(kind, np.full(10, 1.5), pairs=8, seed=0, **HYPER[name])
    _run(ref, lambda X: -_sphere(X), GENS[name], kind == "guided")
    np.testing.assert_array_equal(es.mean, ref.mean)
    np.testing.assert_array_equal(es.best_params, ref.best_params)
    assert es.best_fitness == -ref.best_fitness


def test_maximize_false_state_roundtrip():
    es = CMAES(np.ones(4), sigma=0.3, popsize=6, seed=1, maximize=False)
    assert es.best_fitness == np.inf  # nothing told yet: the worst loss
    for _ in range(3):
        es.tell(_sphere(es.ask()))
    other = CMAES(np.ones(4), sigma=0.3, popsize=6, seed=1, maximize=False)
    other.load_state_dict(es.state_dict())  # the replay negates the same told losses again
    np.testing.assert_array_equal(other.ask(), es.ask())
    assert other.best_fitness == es.best_fitness


@pytest.mark.parametrize("name", ["vanilla", "guided", "cmaes"])
def test_popsize_is_twice_pairs_same_samples(name):
    x0 = np.linspace(-1, 1, 7)
    a = make_strategy(name, x0, pairs=5, seed=3)
    b = make_strategy(name, x0, popsize=10, seed=3)
    c = make_strategy(name, x0, pairs=5, popsize=10, seed=3)  # agreeing values are fine
    assert a.popsize == b.popsize == c.popsize == 10 and a.pairs == b.pairs == 5
    for _ in range(3):
        Xa, Xb, Xc = a.ask(), b.ask(), c.ask()
        np.testing.assert_array_equal(Xa, Xb)
        np.testing.assert_array_equal(Xa, Xc)
        f = -_sphere(Xa)
        a.tell(f), b.tell(f), c.tell(f)
    np.testing.assert_array_equal(a.mean, b.mean)
    # neither given: the default 32 pairs
    assert make_strategy(name, x0).popsize == 64


@pytest.mark.parametrize("cls", [VanillaES, GuidedES, CMAES])
@pytest.mark.parametrize("popsize", [7, 1, 0, -2, 7.5, True, "8"])
def test_bad_popsize_is_one_clear_error(cls, popsize):
    with pytest.raises(ValueError, match=r"popsize must be a positive even integer") as err:
        cls(np.zeros(3), popsize=popsize)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("cls", [VanillaES, GuidedES, CMAES])
def test_conflicting_popsize_and_pairs(cls):
    with pytest.raises(ValueError, match=r"popsize=10 and pairs=4 disagree") as err:
        cls(np.zeros(3), pairs=4, popsize=10)
    assert "\n" not in str(err.value)
    with pytest.raises(ValueError, match="maximize"):
        cls(np.zeros(3), maximize="no")


def test_cmaes_weight_decay_defaults_off_and_moves_the_optimum():
    c = np.array([1.0, -2.0])

    def loss(X):
        return np.sum((np.asarray(X) - c) ** 2, axis=1)

    es = make_strategy("cmaes", np.zeros(2), sigma=0.5, popsize=12, seed=0, maximize=False)
    assert es.weight_decay == 0.0  # Python API: plain CMA-ES
    _run(es, loss, 150, False)
    np.testing.assert_allclose(es.mean, c, atol=1e-6)  # the loss's own optimum

    wd = 0.05  # the paper's setting: minimizes loss + wd * mean(x^2), optimum c / (1 + wd / n)
    es = make_strategy("cmaes", np.zeros(2), sigma=0.5, popsize=12, seed=0, maximize=False, weight_decay=wd)
    _run(es, loss, 150, False)
    np.testing.assert_allclose(es.mean, c / (1 + wd / 2), atol=1e-6)
    assert np.linalg.norm(es.mean - c) > 1e-2


def test_run_config_keeps_the_papers_cmaes_weight_decay():
    cfg = build_config({"env": "CartPole-v1", "method": "cmaes", "es": {"pairs": 3}})
    assert cfg.es.cmaes_weight_decay == 0.05
    es = build_strategy(cfg, np.zeros(5))
    assert isinstance(es, CMAES) and es.weight_decay == 0.05 and es.popsize == 6 and es.maximize
