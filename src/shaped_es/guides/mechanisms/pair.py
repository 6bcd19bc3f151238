"""``shaping.mechanism = pair``: the mean's clone as a search direction (Meier et al. 2019).

After the ES update the mean ``mu_{g+1}`` is cloned (``mean_clone.py``) and the next generation's first
antithetic pair is ``mu_{g+1} +- sigma z_1`` with ``z_1`` along ``theta* - mu_{g+1}`` and of a random
direction's typical length ``sqrt(n)`` (``VanillaES.set_pair_direction``). The gradient estimator is the
usual one, so the pair's return difference weighs the label direction; with a useless direction the
pair is one sample less. No extra rollouts. Logged: ``pair_return_diff`` (F(mu + sigma z_1) -
F(mu - sigma z_1)) and ``clone_step_update_cosine`` (the direction against the ES update it took part in).
"""

from __future__ import annotations

import numpy as np

from shaped_es.guides.mechanisms import Mechanism, every_kth
from shaped_es.guides.mechanisms.candidate import CLONE_METRICS
from shaped_es.guides.mechanisms.mean_clone import clone_mean
from shaped_es.shaping.surrogate import cosine


class MeanPair(Mechanism):
    name = "pair"
    metric_keys = ("pair_return_diff", "clone_step_update_cosine") + CLONE_METRICS

    def __init__(self, host):
        super().__init__(host)
        self.cfg = host.mean_clone_cfg
        self.direction: np.ndarray | None = None  # (n,) the pair's direction in the current generation

    def record_mask(self, population: int, extra: int) -> np.ndarray:
        return every_kth(population, extra, self.cfg.record_every)

    def after_tell(self, generation, params, fitness, extra_returns, results, old_mean, strategy,
                   map_tasks, judged=None) -> dict:
        out: dict = {}
        P = fitness.shape[0] // 2
        if self.direction is not None:  # members 0 and P were mu +- sigma z_1
            es_update = np.asarray(strategy.mean, np.float64) - np.asarray(old_mean, np.float64)
            out.update(pair_return_diff=float(fitness[0] - fitness[P]),
                       clone_step_update_cosine=cosine(self.direction, es_update))
        self.direction = None
        if self.host.labels.ready:
            mu = np.asarray(strategy.mean, np.float64)
            theta_star, info = clone_mean(self.host, generation, mu, self.cfg)
            out.update(info)
            d = theta_star - mu
            if info and np.linalg.norm(d) > 0:
                strategy.set_pair_direction(d)
                self.direction = d
        return out

    def state_dict(self) -> dict[str, np.ndarray]:
        return {"direction": np.zeros(0) if self.direction is None else self.direction.copy()}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        d = np.asarray(state.get("direction", np.zeros(0)), np.float64).reshape(-1)
        if d.size and (d.shape != (self.host.spec.num_params,) or not np.isfinite(d).all()):
            raise ValueError(f"pair direction has shape {d.shape}, expected ({self.host.spec.num_params},)")
        self.direction = d if d.size else None
