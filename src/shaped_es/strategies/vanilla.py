"""Vanilla-ES: isotropic antithetic sampling and the finite-difference mean update (maximizes fitness;
``maximize=False``: minimizes a loss, negated in ``tell``).

Lekkala & Itti, Sec. "Incorporating gradients", Eq. (4)::

    mu_{g+1} = mu_g - gamma * beta / (2 sigma^2 P) * sum_i eps_i [F(mu_g + eps_i) - F(mu_g - eps_i)]

The paper writes the step with a minus sign for a loss; F here is a reward, so we ascend. With
``eps_i = sigma * z_i``, ``z_i ~ N(0, I_n)``, the ascent direction is
``g = 1 / (2 sigma P) * sum_i z_i (F+_i - F-_i)`` after fitness shaping (ranks in [-1, 1] by default);
the paper's ``gamma * beta`` is the optimizer's ``lr`` (``optimizer="sgd"`` with ``momentum=0`` is
exactly Eq. (4); ``"adam"`` is the default). L2 weight decay: ``g -= weight_decay * mu``.

Population layout: ``X = [mu + sigma z_1..P, mu - sigma z_1..P]`` -- row ``i`` and row ``i + P`` mirror
each other about the mean. Generation g's noise comes from ``np.random.default_rng([seed, g])``, so no
RNG state is saved and a resumed run draws the same numbers. ``ask`` draws the noise once a generation
and ``tell`` reuses it: the gradient needs only ``z``, and the best member is rebuilt from its own row.

Directions from outside (the shaped method's label mechanisms, ``guides/mechanisms/``), both for the next
``ask`` only and kept in the state between ``tell`` and ``ask``:

- ``set_pair_direction(d)``: the first antithetic pair goes along ``d`` instead of a random direction
  (Meier et al. 2019, "Improving gradient estimation in evolutionary strategies with past descent
  directions"): ``z_1 = c * d / |d|`` with ``|z_1| = sqrt(n)`` by default, the length a random ``z``
  has on average; the estimator below is unchanged, so the pair's return difference weighs ``d``.
- ``set_mean(x)``: move the mean to ``x`` (an injected solution that selection preferred: CEM-RL,
  Pourchot & Sigaud 2019; Hansen 2011 for CMA-ES); the optimizer's moments are kept.

Large policies (``num_params > float32_above``, default 20,000) take the **float32 path**: the noise is
drawn by :func:`~shaped_es.strategies.fitness.standard_normal_f32` (Box-Muller from the same generator,
~4x faster than ``standard_normal``), kept as float32, and the population ``ask`` returns is float32
(what a policy evaluates anyway); the mean, the gradient and the optimizer state stay float64. Same
distribution, other draws than the float64 path; smaller policies are unchanged (float64, bit for bit).
"""

from __future__ import annotations

import numpy as np

from shaped_es.strategies.base import Strategy
from shaped_es.strategies.fitness import antithetic_gradient, standard_normal_f32

FLOAT32_ABOVE = 20_000  # parameters above which Vanilla/Guided ES take the float32 path (module doc)


class VanillaES(Strategy):
    """Antithetic Vanilla-ES with rank shaping and an SGD/Adam step on the mean.

    Maximizes fitness (``maximize=True``, default); ``maximize=False`` minimizes a loss. Population:
    ``pairs`` antithetic pairs (default 32) or ``popsize`` (even, ``2 * pairs``). ``weight_decay``: L2
    decay on the mean, ``g -= weight_decay * mu`` (0: none).
    """

    # ``ask`` changes nothing ``state_dict`` holds (its noise derives from ``(seed, generation)``): the
    # trainer may ask for the next generation before the current one's checkpoint (``clone_overlap``)
    pure_ask = True

    def __init__(self, x0, sigma: float = 0.1, lr: float = 0.01, pairs: int | None = None,
                 seed: int = 0, fitness_shaping: str = "rank", optimizer: str = "adam",
                 momentum: float = 0.0, weight_decay: float = 0.0,
                 adam_betas: tuple[float, float] = (0.9, 0.999), adam_eps: float = 1e-8,
                 float32_above: int | None = FLOAT32_ABOVE, *, popsize: int | None = None,
                 maximize: bool = True):
        super().__init__(x0, pairs, seed, fitness_shaping, optimizer=optimizer, lr=lr,
                         momentum=momentum, weight_decay=weight_decay, adam_betas=adam_betas,
                         adam_eps=adam_eps, popsize=popsize, maximize=maximize)
        if not sigma > 0:
            raise ValueError(f"sigma must be > 0, got {sigma}")
        if float32_above is not None and (int(float32_above) != float32_above or float32_above < 0):
            raise ValueError(f"float32_above must be a non-negative integer or None, got {float32_above}")
        # float32 path (module doc) above this many parameters; None: always float64
        self.float32 = float32_above is not None and self.num_params > int(float32_above)
        self.sigma = float(sigma)  # search std: eps = sigma * z
        self.lr = float(lr)  # gamma * beta of Eq. (4)
        self._mean = self.x0.copy()  # (n,) mu_g
        self._mean.flags.writeable = False
        self._z: np.ndarray | None = None  # (P, n) directions of the current generation (cache)
        self._pair: np.ndarray | None = None  # (n,) z of the first pair in the next ask (set_pair_direction)
        self._zbuf: np.ndarray | None = None  # (P, n) float32 path: the array _z is drawn into

    @property
    def mean(self) -> np.ndarray:
        """Current mean ``mu_g`` (n,), read-only."""
        return self._mean

    # -- sampling -------------------------------------------------------------------------------
    def _sample_directions(self, rng: np.random.Generator) -> np.ndarray:
        """Directions ``z`` (P, n) in units of sigma: ``eps_i = sigma * z_i``, ``z_i ~ N(0, I_n)``."""
        if self.float32:
            return standard_normal_f32(rng, (self.pairs, self.num_params), out=self._noise_buffer())
        return rng.standard_normal((self.pairs, self.num_params))  # (P, n)

    def _noise_buffer(self) -> np.ndarray:
        """The float32 path's (P, n) noise array, reused across generations (only this generation's
        ``ask``/``tell`` read it; fresh pages of a new one cost as much as drawing into them)."""
        if self._zbuf is None:
            self._zbuf = np.empty((self.pairs, self.num_params), dtype=np.float32)
        return self._zbuf

    def _directions(self) -> np.ndarray:
        if self._z is None:
            rng = np.random.default_rng([self.seed, self.generation])
            z = self._sample_directions(rng)  # (P, n)
            if self._pair is not None:  # the first pair along the given direction (set_pair_direction)
                z[0] = self._pair
            self._z = z
        return self._z

    def _between_generations(self, what: str) -> None:
        if self._z is not None:
            raise RuntimeError(f"{what} called between ask() and tell(); it shapes the next generation")

    def set_pair_direction(self, d, length: float | None = None) -> None:
        """The next ``ask``'s first antithetic pair is ``mu +- sigma * z_1`` with ``z_1`` along ``d`` (n,)
        and ``|z_1| = length`` (default ``sqrt(n)``, a random ``z``'s typical length); ``None`` or a
        zero ``d``: a random pair as usual. Cleared by ``tell``."""
        self._between_generations("set_pair_direction()")
        if d is None:
            self._pair = None
            return
        d = np.asarray(d, dtype=np.float64).reshape(-1)
        if d.shape != (self.num_params,) or not np.isfinite(d).all():
            raise ValueError(f"pair direction must be {self.num_params} finite values, got shape {d.shape}")
        norm = float(np.linalg.norm(d))
        L = np.sqrt(self.num_params) if length is None else float(length)
        if not L > 0:
            raise ValueError(f"pair length must be > 0, got {length}")
        self._pair = None if norm == 0 else (d * (L / norm)).astype(np.float32 if self.float32 else np.float64)

    def set_mean(self, x) -> None:
        """Move the mean to ``x`` (n,) before the next ``ask`` (an injected solution); the optimizer's
        moments are kept, so the next step continues the search's momentum from there."""
        self._between_generations("set_mean()")
        x = np.array(x, dtype=np.float64).reshape(-1)
        if x.shape != (self.num_params,) or not np.isfinite(x).all():
            raise ValueError(f"mean must be {self.num_params} finite values, got shape {x.shape}")
        x.flags.writeable = False
        self._mean = x

    def ask(self) -> np.ndarray:
        """Population ``[mu + sigma z; mu - sigma z]`` (2P, n) (float32 on the float32 path); the same
        values until the next tell (a new array each call)."""
        z = self._directions()  # (P, n)
        if self.float32:
            P, sigma = self.pairs, np.float32(self.sigma)
            X = np.empty((2 * P, self.num_params), dtype=np.float32)  # (2P, n)
            mu = self._mean.astype(np.float32)  # (n,)
            eps = np.empty_like(mu)  # (n,) one row at a time: z is read once, X written once
            for i in range(P):
                np.multiply(z[i], sigma, out=eps)  # eps_i = sigma z_i
                np.add(mu, eps, out=X[i])
                np.subtract(mu, eps, out=X[P + i])
            return X
        eps = self.sigma * z  # (P, n)
        return np.concatenate([self._mean + eps, self._mean - eps], axis=0)  # (2P, n)

    def _member(self, i: int) -> np.ndarray:
        """Row ``i`` of ``ask()`` (the same bits), from its noise row alone."""
        z = self._directions()[i % self.pairs]  # (n,)
        if self.float32:
            eps = np.float32(self.sigma) * z  # (n,) float32
            mu = self._mean.astype(np.float32)
        else:
            eps, mu = self.sigma * z, self._mean
        return mu + eps if i < self.pairs else mu - eps

    # -- update ---------------------------------------------------------------------------------
    def tell(self, fitness, surrogate=None) -> None:
        """Update the mean from this generation's fitness (2P,): larger is better if ``maximize``
        (default), else a loss (smaller is better; negated here).

        ``surrogate`` is accepted for a uniform interface and ignored (see :class:`GuidedES`).
        """
        f = self._score(self._check_fitness(fitness))  # (2P,) to maximize
        z = self._directions()  # (P, n) the noise ask used
        self._record_best(f, self._member)  # rebuilds only the best member's row
        grad = antithetic_gradient(z, self.shape(f), self.sigma)  # (n,)  Eq. (4)
        new_mean = self._ascend(self._mean, grad)  # (n,) gradient ascent (+ weight decay)
        new_mean.flags.writeable = False
        self._mean = new_mean
        self.generation += 1
        self._z = None
        self._pair = None

    # -- state ----------------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """Numpy-only state (no RNG state: noise derives from ``(seed, generation)``)."""
        pair = np.zeros(0) if self._pair is None else np.asarray(self._pair, np.float64).copy()
        return self._base_state() | {"mean": self._mean.copy(), "pair": pair}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        mean = np.array(state["mean"], dtype=np.float64)
        if mean.shape != (self.num_params,):
            raise ValueError(f"mean has shape {mean.shape}, expected ({self.num_params},)")
        pair = np.array(state.get("pair", np.zeros(0)), dtype=np.float64).reshape(-1)  # older states: none
        if pair.shape not in ((0,), (self.num_params,)) or not np.isfinite(pair).all():
            raise ValueError(f"pair has shape {pair.shape}, expected (0,) or ({self.num_params},)")
        self._load_base(state)
        mean.flags.writeable = False
        self._mean = mean
        self._z = None
        self._pair = None if pair.size == 0 else pair.astype(np.float32 if self.float32 else np.float64)
