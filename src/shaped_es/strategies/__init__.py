"""ES strategies over explicit state: Vanilla-ES, Guided ES and CMA-ES (numpy + pycma only).

Every strategy MAXIMIZES fitness by default (``maximize=False``: ``tell`` takes a loss and negates it
internally) and shares one interface::

    es = GuidedES(x0, sigma=0.1, lr=0.2, alpha=0.5, popsize=2, seed=0, fitness_shaping="rank")
    X = es.ask()                    # (popsize, n); popsize = 2 * pairs (antithetic), even
    es.tell(fitness, surrogate=G)   # fitness (popsize,), larger is better; G (k, n) or None
    es.mean, es.popsize, es.pairs, es.generation, es.num_params, es.best_fitness, es.best_params
    es.state_dict() / es.load_state_dict(d)   # numpy arrays only; exact continuation

``make_strategy(name, x0, **hyper)`` builds one by name: ``"vanilla"``, ``"guided"``, ``"cmaes"``.
``pairs=P`` and ``popsize=2 * P`` build the same strategy (the same samples); an odd ``popsize`` or
one that disagrees with ``pairs`` is a ``ValueError``. In this package ``P`` is the number of antithetic
pairs, as in the papers' ``1 / (2 sigma^2 P) * sum_{i=1..P}`` (Eq. (4)): directions are ``(P, n)``, a
population ``(2P, n)``; elsewhere (the trainer, ``shaping/``, ``guides/``) ``P`` is the population size.
CMA-ES ``weight_decay`` defaults to 0.0 here: estool's fitness penalty moves the optimum (see
``cmaes``); the paper's 0.05 is the run config's ``es.cmaes_weight_decay`` default, which the trainer
passes explicitly.

Large policies: above ``float32_above`` parameters (default 20,000) Vanilla and Guided ES draw float32
noise, ``ask`` returns a float32 population and Guided ES keeps its subspace as float32 rows and a small
float64 Cholesky factor (the same covariance; see ``vanilla`` and ``guided``); smaller policies compute
exactly as before, in float64. ``shaped-es bench strategies`` times a generation by size.
"""

from __future__ import annotations

from shaped_es.strategies.base import Strategy
from shaped_es.strategies.cmaes import CMAES
from shaped_es.strategies.guided import GuidedES
from shaped_es.strategies.vanilla import VanillaES

STRATEGIES: dict[str, type[Strategy]] = {"vanilla": VanillaES, "guided": GuidedES, "cmaes": CMAES}


def make_strategy(name: str, x0, **hyper) -> Strategy:
    """Build the strategy called ``name`` (one of :data:`STRATEGIES`) at ``x0`` with ``hyper``
    (its class's keywords, e.g. ``sigma``, ``lr``, ``popsize`` or ``pairs``, ``maximize``, ``seed``).

    >>> es = make_strategy("cmaes", [1.0, -2.0], sigma=0.5, popsize=8, maximize=False)
    >>> X = es.ask(); es.tell(((X - 3.0) ** 2).sum(axis=1))   # a loss: smaller is better
    """
    try:
        cls = STRATEGIES[name]
    except KeyError:
        raise ValueError(f"unknown strategy {name!r}; choose one of {sorted(STRATEGIES)}") from None
    return cls(x0, **hyper)


__all__ = ["CMAES", "GuidedES", "STRATEGIES", "Strategy", "VanillaES", "make_strategy"]
