"""Vanilla-ES: isotropic antithetic sampling and the finite-difference mean update (maximize).

Lekkala & Itti, Sec. "Incorporating gradients", Eq. (4)::

    mu_{g+1} = mu_g - gamma * beta / (2 sigma^2 P) * sum_i eps_i [F(mu_g + eps_i) - F(mu_g - eps_i)]

The paper writes the step with a minus sign for a loss; F here is a reward, so we ascend. With
``eps_i = sigma * z_i``, ``z_i ~ N(0, I_n)``, the ascent direction is
``g = 1 / (2 sigma P) * sum_i z_i (F+_i - F-_i)`` after fitness shaping (ranks in [-1, 1] by default);
the paper's ``gamma * beta`` is the optimizer's ``lr`` (``optimizer="sgd"`` with ``momentum=0`` is
exactly Eq. (4); ``"adam"`` is the default). L2 weight decay: ``g -= weight_decay * mu``.

Population layout: ``X = [mu + sigma z_1..P, mu - sigma z_1..P]`` -- row ``i`` and row ``i + P`` mirror
each other about the mean. Generation g's noise comes from ``np.random.default_rng([seed, g])``, so no
RNG state is saved and a resumed run draws the same numbers.
"""

from __future__ import annotations

import numpy as np

from shaped_es.strategies.base import Strategy
from shaped_es.strategies.fitness import antithetic_gradient


class VanillaES(Strategy):
    """Antithetic Vanilla-ES with rank shaping and an SGD/Adam step on the mean (maximizes fitness)."""

    def __init__(self, x0, sigma: float = 0.1, lr: float = 0.01, pairs: int = 32, seed: int = 0,
                 fitness_shaping: str = "rank", optimizer: str = "adam", momentum: float = 0.0,
                 weight_decay: float = 0.0, adam_betas: tuple[float, float] = (0.9, 0.999),
                 adam_eps: float = 1e-8):
        super().__init__(x0, pairs, seed, fitness_shaping, optimizer=optimizer, lr=lr,
                         momentum=momentum, weight_decay=weight_decay, adam_betas=adam_betas,
                         adam_eps=adam_eps)
        if not sigma > 0:
            raise ValueError(f"sigma must be > 0, got {sigma}")
        self.sigma = float(sigma)  # search std: eps = sigma * z
        self.lr = float(lr)  # gamma * beta of Eq. (4)
        self._mean = self.x0.copy()  # (n,) mu_g
        self._mean.flags.writeable = False
        self._z: np.ndarray | None = None  # (P, n) directions of the current generation (cache)

    @property
    def mean(self) -> np.ndarray:
        """Current mean ``mu_g`` (n,), read-only."""
        return self._mean

    # -- sampling -------------------------------------------------------------------------------
    def _sample_directions(self, rng: np.random.Generator) -> np.ndarray:
        """Directions ``z`` (P, n) in units of sigma: ``eps_i = sigma * z_i``, ``z_i ~ N(0, I_n)``."""
        return rng.standard_normal((self.pairs, self.num_params))  # (P, n)

    def _directions(self) -> np.ndarray:
        if self._z is None:
            rng = np.random.default_rng([self.seed, self.generation])
            self._z = self._sample_directions(rng)  # (P, n)
        return self._z

    def ask(self) -> np.ndarray:
        """Population ``[mu + sigma z; mu - sigma z]`` (2P, n); the same array until the next tell."""
        eps = self.sigma * self._directions()  # (P, n)
        return np.concatenate([self._mean + eps, self._mean - eps], axis=0)  # (2P, n)

    # -- update ---------------------------------------------------------------------------------
    def tell(self, fitness, surrogate=None) -> None:
        """Update the mean from this generation's fitness (2P,), larger is better.

        ``surrogate`` is accepted for a uniform interface and ignored (see :class:`GuidedES`).
        """
        f = self._check_fitness(fitness)  # (2P,)
        z = self._directions()  # (P, n)
        self._record_best(f, self.ask())
        grad = antithetic_gradient(z, self.shape(f), self.sigma)  # (n,)  Eq. (4)
        new_mean = self._ascend(self._mean, grad)  # (n,) gradient ascent (+ weight decay)
        new_mean.flags.writeable = False
        self._mean = new_mean
        self.generation += 1
        self._z = None

    # -- state ----------------------------------------------------------------------------------
    def state_dict(self) -> dict[str, np.ndarray]:
        """Numpy-only state (no RNG state: noise derives from ``(seed, generation)``)."""
        return self._base_state() | {"mean": self._mean.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        mean = np.array(state["mean"], dtype=np.float64)
        if mean.shape != (self.num_params,):
            raise ValueError(f"mean has shape {mean.shape}, expected ({self.num_params},)")
        self._load_base(state)
        mean.flags.writeable = False
        self._mean = mean
        self._z = None
