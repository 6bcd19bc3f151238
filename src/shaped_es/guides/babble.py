"""Motor babbling for M_phi's data (``shaping.inverse_dynamics.babble``): random policies rolled out
beside the first generations' populations.

Inverse-dynamics models learn from exploratory data (Jordan & Rumelhart 1992; Agrawal et al. 2016):
``b`` policies with weights ~ N(0, babble_sigma^2), whose saturated tanh outputs drive the agent through
actions the first, near-still populations never take. The shaped guide (``shaped.py``; its rollout hooks,
``shaped_rollouts.py``) evaluates them as extra members after the mechanism's own; their steps are M_phi's
data and the clone's states, their returns steer no ES step. The guide stops asking for them once its label
budget has slept (the run judged its labels as losing: a wake-up trial runs without them). Stateless: drawn
from the run's seed and the generation, so a resumed run draws the same.
"""

from __future__ import annotations

import numpy as np

from shaped_es import seeding

BABBLE_KEY = 1_000_007  # the seed key of the babbling policies (members use 0..P-1, the clone 1_000_003)


def babbling_policies(settings, seed: int, generation: int, num_params: int) -> np.ndarray | None:
    """The babblers ``(b, num_params)`` float32 of ``generation`` (``settings``: the config's
    ``shaping.inverse_dynamics``), or None once ``babble_generations`` have passed or with ``babble = 0``."""
    if not settings.babble or generation >= settings.babble_generations:
        return None
    rng = np.random.default_rng(seeding.derive_seed(seed, seeding.SHAPING, generation, BABBLE_KEY))
    return (rng.standard_normal((settings.babble, num_params)) * settings.babble_sigma).astype(np.float32)
