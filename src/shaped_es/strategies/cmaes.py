"""CMA-ES baseline: a thin adapter over pycma's ``cma.CMAEvolutionStrategy`` (maximizes fitness;
``maximize=False``: minimizes a loss).

Lekkala & Itti, Eqs. (1)-(2): the mean and covariance are re-estimated from the ``M_best`` (25) best
members each generation; pycma implements the full CMA-ES (Hansen 2016) with ``CMA_mu = M_best``.
Settings as the paper's baseline:

- population ``2 * pairs`` (or ``popsize``, even); ``mu`` (M_best) clipped to ``popsize // 2``;
- weight decay on the fitness, as in estool: ``fitness_i -= weight_decay * mean(x_i ** 2)`` (with
  ``maximize=False``: ``loss_i += weight_decay * mean(x_i ** 2)``). This changes the objective, so it
  MOVES THE OPTIMUM towards 0: ``||x - c||^2`` in n dimensions is then minimized at
  ``c / (1 + weight_decay / n)``, and the flatter the objective the larger the shift. The paper's
  baseline uses 0.05 (on episode returns): the run config's ``es.cmaes_weight_decay`` keeps 0.05 and the
  trainer passes it; the Python API defaults to ``weight_decay=0.0`` (plain CMA-ES, no shift);
- above ``diagonal_above`` parameters the full covariance (O(n^2) memory, O(n^3) updates) is replaced
  by the separable/diagonal variant (pycma option ``CMA_diagonal=True``; the paper notes full CMA-ES is
  infeasible beyond ~10k parameters).

pycma minimizes, so it is told ``-fitness`` (the loss itself if ``maximize=False``). pycma draws from
numpy's GLOBAL random state; every call into pycma runs with a private global state (the caller's is
saved and restored around it), so the strategy is deterministic whatever else runs in the process and
leaves others' draws untouched.

Exact resume without pickle: ``state_dict`` keeps the told fitness history (G, popsize);
``load_state_dict`` rebuilds pycma from ``x0`` with the same seed and replays the G ask/tell rounds,
which reproduces every internal array bit for bit (checked against the saved mean).
"""

from __future__ import annotations

import numpy as np

from shaped_es.strategies.base import Strategy
from shaped_es.strategies.fitness import l2_fitness_penalty


class CMAES(Strategy):
    """pycma CMA-ES (separable above ``diagonal_above`` params) behind the common ask/tell API.

    Maximizes fitness (``maximize=True``, default); ``maximize=False`` minimizes a loss. ``pairs``
    (default 32) or ``popsize`` (even, ``2 * pairs``). ``weight_decay`` (default 0.0): estool's fitness
    penalty ``wd * mean(x ** 2)``, which moves the optimum towards 0 (module doc); the paper's baseline,
    and the run config's ``es.cmaes_weight_decay``, use 0.05.
    """

    def __init__(self, x0, sigma: float = 0.1, pairs: int | None = None, seed: int = 0,
                 weight_decay: float = 0.0, mu: int = 25, diagonal_above: int = 2000, *,
                 popsize: int | None = None, maximize: bool = True):
        super().__init__(x0, pairs, seed, fitness_shaping="none", weight_decay=weight_decay,
                         popsize=popsize, maximize=maximize)
        if not sigma > 0:
            raise ValueError(f"sigma must be > 0, got {sigma}")
        if int(mu) != mu or mu < 1:
            raise ValueError(f"mu must be a positive integer, got {mu}")
        self.sigma0 = float(sigma)  # initial step size
        self.mu = max(1, min(int(mu), self.popsize // 2))  # M_best parents
        self.diagonal = self.num_params > diagonal_above  # separable CMA-ES for large n
        self.jump_resets_paths = True  # set_mean zeroes the evolution paths (False: a checkpoint from before)
        self._build()

    # -- pycma plumbing -----------------------------------------------------------------------
    def _options(self) -> dict:
        return {
            "popsize": self.popsize,
            "CMA_mu": self.mu,
            "CMA_diagonal": bool(self.diagonal),
            "seed": np.nan,  # pycma must not reseed: we own the global state it draws from
            "verbose": -9, "verb_disp": 0, "verb_log": 0, "verb_plot": 0, "verb_time": False,
        }

    def _build(self) -> None:
        import cma  # here, not at the top: pycma imports scipy.stats (~1 s), which a run of another method need not

        self._rng_state = np.random.RandomState(self.seed).get_state()  # our private global state
        self._es = self._isolated(lambda: cma.CMAEvolutionStrategy(self.x0.copy(), self.sigma0,
                                                                   self._options()))
        self._pending: list[np.ndarray] | None = None  # solutions asked, awaiting tell
        self._history: list[np.ndarray] = []  # told raw fitness, one (popsize,) row per generation
        self._jumps: dict[int, np.ndarray] = {}  # generation -> the mean set_mean moved to (replayed)

    def _isolated(self, fn):
        """Run ``fn`` with our numpy global RNG state; restore the caller's afterwards."""
        caller = np.random.get_state()
        np.random.set_state(self._rng_state)
        try:
            return fn()
        finally:
            self._rng_state = np.random.get_state()
            np.random.set_state(caller)

    # -- ask / tell ---------------------------------------------------------------------------
    @property
    def mean(self) -> np.ndarray:
        """pycma's current distribution mean (n,) (a copy; no bounds or scaling, so pheno == geno)."""
        return np.array(self._es.mean, dtype=np.float64)

    def ask(self) -> np.ndarray:
        """Population (popsize, n); the same until the next tell."""
        if self._pending is None:
            self._pending = self._isolated(self._es.ask)
        return np.array(self._pending, dtype=np.float64)  # (2P, n)

    def search_scale(self) -> float:
        """The root mean square of pycma's per-coordinate standard deviations (``sigma * sqrt(diag C)``,
        adapted generation by generation; ``sigma0`` before the first ``tell``)."""
        return float(np.sqrt(np.mean(np.square(self._es.stds))))

    def tell(self, fitness, surrogate=None) -> None:
        """Update from fitness (popsize,): larger is better if ``maximize`` (default), else a loss.
        ``surrogate`` is accepted and ignored."""
        f = self._check_fitness(fitness)  # (2P,) as told (the history replays it)
        score = self._score(f)  # (2P,) to maximize
        if self._pending is None:
            self.ask()
        solutions = self._pending  # 2P rows of (n,), as asked (no copy of the population)
        self._record_best(score, lambda i: solutions[i])
        penalized = l2_fitness_penalty(score, solutions, self.weight_decay)  # (2P,) estool weight decay
        self._isolated(lambda: self._es.tell(solutions, (-penalized).tolist()))  # pycma minimizes
        self._pending = None
        self._history.append(f.copy())
        self.generation += 1

    def set_mean(self, x) -> None:
        """Move the mean to ``x`` (n,) before the next ``ask`` (an accepted candidate of the shaped
        method): pycma's mean is set as it is, with step size and covariance kept -- a jump CMA's own
        update did not make, so its evolution paths do not learn from it (Hansen 2011's injection would; an
        injected solution moves the mean by one member's weight, too little for a jump). The paths
        (``ps``, cumulative step-size adaptation's, and ``pc``, the rank-one update's) are zeroed: they sum
        the old mean's recent moves, and after a jump those are another region's. Kept, they let the
        steps that follow a jump (the ES pulling back toward where it was) read as a long consistent path,
        and the step size grew jump after jump: on ReacherWay-v0 sigma went 0.12 -> 0.26 over 40 generations
        of jumps, the population's mean return -22 -> -55, while the jumped mean itself held at -8 to -15
        (``docs/benchmarks/shaped_cmaes_suite``). The jump is recorded, and the replay of
        ``load_state_dict`` repeats it (a checkpoint from before the reset replays without it)."""
        if self._pending is not None:
            raise RuntimeError("set_mean() between ask() and tell()")
        x = np.array(x, dtype=np.float64).reshape(-1)
        if x.shape != (self.num_params,) or not np.isfinite(x).all():
            raise ValueError(f"mean must be {self.num_params} finite values, got shape {x.shape}")
        self._es.mean[:] = x
        if self.jump_resets_paths:
            for path in (getattr(self._es.adapt_sigma, "ps", None), getattr(self._es, "pc", None)):
                if isinstance(path, np.ndarray):
                    path[:] = 0
        self._jumps[self.generation] = x.copy()

    # -- state --------------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        hist = np.array(self._history, dtype=np.float64).reshape(len(self._history), self.popsize)
        gens = sorted(self._jumps)
        jumps = np.array([[g, *self._jumps[g]] for g in gens], np.float64).reshape(len(gens), self.num_params + 1)
        return self._base_state() | {"fitness_history": hist, "mean": self.mean,  # hist (G, 2P)
                                     "jumps": jumps,  # (J, 1 + n): generation, the mean moved to
                                     "jump_resets_paths": np.array(int(self.jump_resets_paths), np.int64)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        """Rebuild pycma from x0 and replay the saved generations (bitwise-exact continuation)."""
        hist = np.array(state["fitness_history"], dtype=np.float64)  # (G, 2P)
        if hist.ndim != 2 or hist.shape[1] != self.popsize:
            raise ValueError(f"fitness_history has shape {hist.shape}, expected (G, {self.popsize})")
        if int(np.asarray(state["generation"])) != hist.shape[0]:
            raise ValueError("fitness_history length does not match generation")
        jumps = np.asarray(state.get("jumps", np.zeros((0, self.num_params + 1))), np.float64)
        if jumps.ndim != 2 or jumps.shape[1] != self.num_params + 1:
            raise ValueError(f"jumps has shape {jumps.shape}, expected (J, {self.num_params + 1})")
        self._build()
        self.generation = 0
        self.jump_resets_paths = bool(np.asarray(state.get("jump_resets_paths", 0)))  # absent: an older run's
        moves = {int(j[0]): j[1:] for j in jumps}
        if 0 in moves:
            self.set_mean(moves[0])
        for row in hist:
            self.tell(row)
            if self.generation in moves:
                self.set_mean(moves[self.generation])
        self._load_base(state)  # best-so-far as saved (the replay recomputed the same)
        saved = np.asarray(state["mean"], dtype=np.float64)
        if not np.array_equal(saved, self.mean):
            raise ValueError("CMA-ES replay did not reproduce the saved mean (different pycma/numpy?)")
