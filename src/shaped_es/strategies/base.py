"""Common base of every strategy: generation counter, best-so-far, fitness shaping, optimizer step.

Conventions (all strategies):

- **Maximize**: ``tell`` takes fitness where larger is better (episode return).
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


class Strategy:
    """Shared state and helpers; see the module docstring for the contract."""

    def __init__(self, x0, pairs: int, seed: int, fitness_shaping: str = "none",
                 optimizer: str | None = None, lr: float = 0.01, momentum: float = 0.0,
                 weight_decay: float = 0.0, adam_betas: tuple[float, float] = (0.9, 0.999),
                 adam_eps: float = 1e-8):
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
        self.generation = 0  # number of tells so far
        self.best_fitness = -np.inf  # best fitness ever told (raw, before shaping)
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

    # -- helpers ------------------------------------------------------------------------------
    def _check_fitness(self, fitness) -> np.ndarray:
        f = np.asarray(fitness, dtype=np.float64)
        if f.shape != (self.popsize,):
            raise ValueError(f"fitness must have shape ({self.popsize},), got {f.shape}")
        if not np.isfinite(f).all():
            raise ValueError("fitness must be finite (got NaN or inf)")
        return f

    def _record_best(self, fitness: np.ndarray, population) -> None:
        """Best-so-far from ``fitness`` (N,); ``population`` is an (N, n) array, or a function of the
        member index returning its (n,) parameters (so a strategy need not rebuild the population)."""
        i = int(np.argmax(fitness))
        if fitness[i] > self.best_fitness:
            row = population(i) if callable(population) else population[i]
            self.best_fitness = float(fitness[i])
            self.best_params = np.array(row, dtype=np.float64)

    def shape(self, fitness: np.ndarray) -> np.ndarray:
        """This strategy's fitness shaping (``fitness_shaping``) applied to ``fitness``."""
        return shape_fitness(fitness, self.fitness_shaping)

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
