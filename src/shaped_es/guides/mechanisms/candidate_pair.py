"""``shaping.mechanism = candidate_pair``: both uses of the mean's clone at once.

The clone ``theta*`` of the mean is evaluated as a candidate that replaces the mean when it beats every
member (``candidate.py``), and its direction ``theta* - mu`` is also the next generation's first
antithetic pair (``pair.py``), so a rejected clone still informs the gradient estimate. One clone, the
candidate mechanism's extra rollouts, no more.
"""

from __future__ import annotations

import numpy as np

from shaped_es.guides.mechanisms.candidate import MeanCandidate


class MeanCandidatePair(MeanCandidate):
    name = "candidate_pair"
    metric_keys = MeanCandidate.metric_keys + ("pair_return_diff",)

    def after_tell(self, generation, params, fitness, extra_returns, results, old_mean, strategy,
                   map_tasks) -> dict:
        paired = self.extras is not None  # this generation's first pair lay along the clone direction
        out = super().after_tell(generation, params, fitness, extra_returns, results, old_mean, strategy,
                                 map_tasks)
        if paired:
            P = fitness.shape[0] // 2
            out["pair_return_diff"] = float(fitness[0] - fitness[P])
        if self.extras is not None:  # the new clone: its direction is the next generation's first pair
            d = self.extras[0].astype(np.float64) - self.extras[-1]
            if np.linalg.norm(d) > 0:
                strategy.set_pair_direction(d)
        return out

