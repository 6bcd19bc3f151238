"""What the shaped guide asks of each generation's rollouts, the hooks the trainer calls when it builds their
tasks: which members run beyond the population (the mechanism's extra members, then the babbling policies of
the first generations: ``guides/babble.py``) and with how many more episodes, whose steps are recorded (the
mechanism's mask, every babbler; none while the guide sleeps), whether the env controller's actions are
recorded too (``shaping.labels = controller``), and who writes the recorded steps' shards (the workers
placement's tasks, before they return; the master's writer thread otherwise).

``RolloutHooks`` is a part of ``guides/shaped.py``'s ``ShapedGuide`` (its base class), which owns the state these
methods use: ``labels``, ``awake``, ``mechanism``, ``mphi``, ``budget``, ``sh``, ``cfg``, ``spec``, ``placement``,
``traj_root`` and ``_babblers`` (babbling policies among this generation's extra members).
"""

from __future__ import annotations

import functools

import numpy as np

from shaped_es.guides.babble import babbling_policies
from shaped_es.guides.shaped_tasks import rollout_and_store


class RolloutHooks:
    """The rollout hooks of a :class:`~shaped_es.guides.shaped.ShapedGuide` (the module docstring names the
    guide's attributes these methods use)."""

    @property
    def expert(self) -> bool:
        """The rollouts record the env controller's actions (``shaping.labels = controller``)."""
        return self.labels.records_expert

    def record_mask(self, population: int, extra: int) -> np.ndarray:
        """Which members' steps the rollouts keep (the mechanism's choice; every babbler),
        ``(population + extra,)``."""
        if not self.awake:
            return np.zeros(population + extra, bool)
        mask = self.mechanism.record_mask(population, extra)
        if self._babblers:
            mask[population + extra - self._babblers:] = True
        return mask

    def extra_members(self, generation: int) -> np.ndarray | None:
        """Policies ``(k, n)`` evaluated beside the population (None: none): the mechanism's, then the
        babbling policies of the first generations (``guides/babble.py``; M_phi's data only); none while
        the guide sleeps, and none once it has slept (the budget judged the labels as losing; M_phi has its
        first generations' data: a wake-up trial runs without babblers; the budget's state is checkpointed,
        so a resumed run draws the same)."""
        if not self.awake:
            self._babblers = 0
            return None
        mech = self.mechanism.extra_members(generation)
        bab = None if self.mphi is None or self.budget.sleeps else babbling_policies(
            self.sh.inverse_dynamics, self.cfg.seed, generation, self.spec.num_params)  # (b, n)
        self._babblers = 0 if bab is None else bab.shape[0]
        if bab is None:
            return mech
        return bab if mech is None else np.concatenate([np.asarray(mech, np.float32), bab])  # (k + b, n)

    def extra_episodes(self) -> int:
        """Episodes the mechanism's extra members run beyond the population's."""
        return self.mechanism.extra_episodes if self.awake else 0

    def unjudged_extras(self) -> int:
        """The babblers (the last extras): M_phi's data only, never judged, so the population's episodes."""
        return self._babblers

    def rollout_fn(self):
        if self.placement == "workers":  # each worker writes its chunk's shard before it returns
            return functools.partial(rollout_and_store, traj_root=self.traj_root)
        # master: the transitions come back with the returns and the master writes one shard in its
        # writer thread while it clones (worker-side writes put ~10 ms on the rollouts' critical path)
        return None
