"""Common base of every strategy: generation counter, best-so-far, fitness shaping, optimizer step.

Conventions (all strategies):

- **Maximize** by default: ``tell`` takes fitness where larger is better (episode return).
  ``maximize=False`` makes ``tell`` take a loss (smaller is better): it is negated internally, before
  fitness shaping and weight decay, so every update is the maximizing one on ``-loss``; ``best_fitness``
  stays in the caller's units (the lowest loss told; ``+inf`` before the first tell).
- **Population size**: ``pairs`` antithetic pairs, or ``popsize`` (even, ``= 2 * pairs``) as evosax and
  EvoTorch users write it; ``popsize=2 * P`` builds exactly the strategy ``pairs=P`` does (the same
  samples). Neither given: :data:`DEFAULT_PAIRS` pairs.
- ``ask()`` is idempotent within a generation: it returns the same population until ``tell``.
- ``state_dict()`` holds only numpy arrays (scalars as 0-d arrays, no object arrays), so it saves with
  ``np.savez`` and loads with ``allow_pickle=False``; ``load_state_dict`` on an instance built with the
  same hyperparameters continues bit for bit like an uninterrupted run.

Subclasses implement ``ask``, ``tell`` and the ``mean`` property.
"""

from __future__ import annotations

import numpy as np

from shaped_es.strategies.fitness import SHAPINGS, l2_decay, shape_fitness
from shaped_es.strategies.optim import make_optimizer


DEFAULT_PAIRS = 32  # antithetic pairs when neither pairs nor popsize is given (population 64)


def resolve_pairs(pairs: int | None, popsize: int | None) -> int:
    """Antithetic pairs from ``pairs`` and/or ``popsize`` (even, ``2 * pairs``); one-line ValueError
    for an odd, non-positive or non-integer ``popsize`` or one that disagrees with ``pairs``."""
    if popsize is None:
        return DEFAULT_PAIRS if pairs is None else pairs
    try:
        ok = not isinstance(popsize, bool) and int(popsize) == popsize and popsize >= 2 and popsize % 2 == 0
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok:
        raise ValueError(f"popsize must be a positive even integer (antithetic pairs: popsize = "
                         f"2 * pairs), got {popsize!r}")
    if pairs is not None and 2 * pairs != popsize:
        raise ValueError(f"popsize={popsize} and pairs={pairs} disagree (popsize = 2 * pairs); "
                         f"give one of them")
    return int(popsize) // 2


class Strategy:
    """Shared state and helpers; see the module docstring for the contract."""

    def __init__(self, x0, pairs: int | None, seed: int, fitness_shaping: str = "none",
                 optimizer: str | None = None, lr: float = 0.01, momentum: float = 0.0,
                 weight_decay: float = 0.0, adam_betas: tuple[float, float] = (0.9, 0.999),
                 adam_eps: float = 1e-8, *, popsize: int | None = None, maximize: bool = True):
        pairs = resolve_pairs(pairs, popsize)
        if not isinstance(maximize, (bool, np.bool_)):
            raise ValueError(f"maximize must be True (fitness: larger is better) or False (a loss), "
                             f"got {maximize!r}")
        x0 = np.array(x0, dtype=np.float64)
        if x0.ndim != 1 or x0.shape[0] == 0 or not np.isfinite(x0).all():
            raise ValueError(f"x0 must be a finite non-empty 1-D vector, got shape {x0.shape}")
        if int(pairs) != pairs or pairs < 1:
            raise ValueError(f"pairs must be a positive integer, got {pairs}")
        if int(seed) != seed or seed < 0:
            raise ValueError(f"seed must be a non-negative integer, got {seed}")
        if fitness_shaping not in SHAPINGS:
            raise ValueError(f"unknown fitness_shaping {fitness_shaping!r}; choose one of {SHAPINGS}")
        if not weight_decay >= 0:
            raise ValueError(f"weight_decay must be >= 0, got {weight_decay}")
        self.x0 = x0  # (n,) initial mean (kept for strategies that rebuild from it)
        self.num_params = int(x0.shape[0])  # n
        self.pairs = int(pairs)  # P antithetic pairs
        self.popsize = 2 * self.pairs  # members per generation
        self.seed = int(seed)  # strategy seed; generation g draws from default_rng([seed, g])
        self.fitness_shaping = fitness_shaping  # "rank" (paper) or "none"
        self.weight_decay = float(weight_decay)
        self.maximize = bool(maximize)  # False: tell takes a loss and negates it internally
        self.generation = 0  # number of tells so far
        # best fitness ever told (raw, before shaping, in the caller's units: the lowest loss if not
        # maximize)
        self.best_fitness = -np.inf if self.maximize else np.inf
        self.best_params = x0.copy()  # (n,) member that got it (x0 until the first tell)
        self.opt = None if optimizer is None else make_optimizer(
            optimizer, self.num_params, lr, momentum, adam_betas, adam_eps)

    # -- subclass contract ----------------------------------------------------------------------
    @property
    def mean(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def ask(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def tell(self, fitness, surrogate=None) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def search_scale(self) -> float:
        """The next ``ask``'s typical perturbation per coordinate: the root mean square of its standard
        deviations (``sigma`` where the search is isotropic; the shaped method's clone noise is in these units)."""
        return float(self.sigma)

    # -- helpers ------------------------------------------------------------------------------
    def _check_fitness(self, fitness) -> np.ndarray:
        f = np.asarray(fitness, dtype=np.float64)
        if f.shape != (self.popsize,):
            raise ValueError(f"fitness must have shape ({self.popsize},), got {f.shape}")
        if not np.isfinite(f).all():
            raise ValueError("fitness must be finite (got NaN or inf)")
        return f

    def _score(self, fitness: np.ndarray) -> np.ndarray:
        """The value every update maximizes: ``fitness`` itself, or ``-fitness`` if not ``maximize``."""
        return fitness if self.maximize else -fitness

    def _record_best(self, score: np.ndarray, population) -> None:
        """Best-so-far from ``score`` (N,) (:meth:`_score`, larger is better); ``population`` is an
        (N, n) array, or a function of the member index returning its (n,) parameters (so a strategy
        need not rebuild the population). ``best_fitness`` is kept in the caller's units."""
        i = int(np.argmax(score))
        if score[i] > (self.best_fitness if self.maximize else -self.best_fitness):
            row = population(i) if callable(population) else population[i]
            self.best_fitness = float(score[i]) if self.maximize else -float(score[i])
            self.best_params = np.array(row, dtype=np.float64)

    def shape(self, fitness: np.ndarray) -> np.ndarray:
        """This strategy's fitness shaping (``fitness_shaping``) applied to ``fitness``."""
        return shape_fitness(fitness, self.fitness_shaping)

    def reset_momentum(self) -> None:
        """Forget the optimizer's momentum (no optimizer: nothing to forget). The shaped method calls it
        after moving the mean to an accepted candidate: the momentum holds gradients estimated around
        the old mean, and carries the next steps away from the new one."""
        if self.opt is not None:
            self.opt.reset_momentum()

    def _ascend(self, mean: np.ndarray, grad: np.ndarray) -> np.ndarray:
        """One optimizer step of ``mean`` along ``grad`` after L2 weight decay on the mean."""
        g = l2_decay(grad, mean, self.weight_decay)  # (n,) grad of F - wd/2 ||mu||^2
        return self.opt.step(mean, g)

    # -- state ---------------------------------------------------------------------------------
    def _base_state(self) -> dict[str, np.ndarray]:
        out = {
            "generation": np.array(self.generation, dtype=np.int64),
            "best_fitness": np.array(self.best_fitness, dtype=np.float64),
            "best_params": self.best_params.copy(),
        }
        if self.opt is not None:
            out |= {f"opt/{k}": v for k, v in self.opt.state_dict().items()}
        return out

    def _load_base(self, state: dict[str, np.ndarray]) -> None:
        best = np.array(state["best_params"], dtype=np.float64)
        if best.shape != (self.num_params,):
            raise ValueError(f"best_params has shape {best.shape}, expected ({self.num_params},)")
        generation = int(np.asarray(state["generation"]))
        if generation < 0:
            raise ValueError(f"generation must be >= 0, got {generation}")
        if self.opt is not None:
            self.opt.load_state_dict({k[4:]: v for k, v in state.items() if k.startswith("opt/")})
        self.generation = generation
        self.best_fitness = float(np.asarray(state["best_fitness"]))
        self.best_params = best
