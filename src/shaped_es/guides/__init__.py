"""Per-method hooks around the generation loop: what to record and which surrogate shapes the next ask.

- ``vanilla`` / ``cmaes``: :class:`NoGuide` (nothing extra).
- ``guided``: :class:`PastUpdateGuide`, Guided ES with the last ``k`` ES updates of the mean as the
  surrogate subspace (no waypoints needed; a cheap, environment-agnostic baseline).
- ``shaped``: the paper's Algorithm 1 (``guides/shaped.py``): inverse dynamics + behaviour cloning.

A guide sees the strategy and a ``map_tasks(fn, tasks)`` callable from the trainer, never an executor.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

import numpy as np

MapTasks = Callable[[Callable[[Any], Any], Sequence[Any]], list[Any]]


class NoGuide:
    """Plain ES: rollouts keep no transitions, the strategy gets no surrogate."""

    record = False
    expert = False  # rollouts also record the env's waypoint controller's actions
    position_period = None  # (d,): the rollouts take info['position'] modulo it (RolloutTask.position_period)
    # es.obs_norm: the normalizer the next generation's members see (policies.ObsNorm; None: off), set by
    # the trainer before each after_tell (the shaped guide fits its clones through it)
    obs_norm = None
    # env steps and seconds the guide spent before generation 0 (the shaped guide's label probe); the
    # trainer counts them in the first generation it runs, then sets this to (0, 0.0)
    startup: tuple[int, float] = (0, 0.0)

    def begin_generation(self, generation: int) -> None:
        """Called before the rollouts start (background work may start here)."""

    def record_mask(self, population: int, extra: int) -> np.ndarray:
        """Which members' steps the rollouts keep, ``(population + extra,)`` bool (``record``: all or none)."""
        return np.full(population + extra, bool(self.record))

    def extra_members(self, generation: int) -> np.ndarray | None:
        """Policies ``(k, n)`` to evaluate beside the population on its episodes (None: none); their
        results follow the population's in ``after_tell``'s ``results`` (members ``P .. P + k - 1``)."""
        return None

    def extra_episodes(self) -> int:
        """Episodes the judged extra members run beyond the population's (their first ones are the
        population's)."""
        return 0

    def unjudged_extras(self) -> int:
        """How many of the last extra members are never judged (data only: they run the population's
        episodes, not ``extra_episodes`` more)."""
        return 0

    def rollout_fn(self):
        """Worker-side function for training rollouts (None: the plain ``rollout.run_task``)."""
        return None

    def after_tell(self, generation, params, results, old_mean, strategy, map_tasks: MapTasks,
                   ready=None) -> dict:
        """Called after ``strategy.tell``; may call ``strategy.guide(G)``; returns extra metrics (only
        the columns :meth:`metric_keys` declares may hold a value). ``ready(mask)`` (None: not offered):
        a guide with slow work left that changes neither the strategy nor the next generation's population
        may call it once, before that work, with that population's record mask ``(P,)``; the trainer then
        starts the population's rollouts meanwhile (``clone_overlap``)."""
        return {}

    def metric_keys(self) -> tuple[str, ...]:
        """The ``metrics.csv`` columns ``after_tell`` fills with this guide's config, beyond the run
        loop's own (``run_loop.BASE_COLUMNS``): the header holds these and no column that always stays
        empty."""
        return ()

    def state_dict(self) -> dict[str, np.ndarray]:
        return {}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        pass

    def close(self) -> None:
        pass


class PastUpdateGuide(NoGuide):
    """Guided ES whose surrogate gradients are the last ``k`` updates ``mu_{g+1} - mu_g``."""

    def __init__(self, k: int = 1):
        self.k = k
        self.history: list[np.ndarray] = []

    def after_tell(self, generation, params, results, old_mean, strategy, map_tasks, ready=None) -> dict:
        step = np.asarray(strategy.mean, dtype=np.float64) - np.asarray(old_mean, dtype=np.float64)
        if np.linalg.norm(step) > 0:
            self.history = (self.history + [step])[-self.k :]
        if self.history:
            strategy.guide(np.stack(self.history))  # (k, n)
        return {}

    def state_dict(self) -> dict[str, np.ndarray]:
        n = 0 if not self.history else self.history[0].shape[0]
        hist = np.stack(self.history) if self.history else np.zeros((0, n))
        return {"history": hist}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.history = [row for row in state.get("history", np.zeros((0, 0)))]
