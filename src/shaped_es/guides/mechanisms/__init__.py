"""How the shaped method's labels become search (``shaping.mechanism``), one file a mechanism.

The guide (``guides/shaped.py``) owns the data (every generation's recorded steps, in memory and in the
trajectory store: ``guides/shaped_data.py``), ``M_phi`` and the label source (``shaping/labels.py``); a mechanism decides what is
cloned and how the clone reaches the ES strategy:

==============  ==========================================================================================
mechanism       what it does with the labels
==============  ==========================================================================================
``paper``       every member is cloned toward the labels on its own data ``D_i``; ``Delta = (theta* -
                mu_{g+1}) / eta`` spans the next generation's Guided-ES subspace (the paper, Algorithm 1)
``candidate``   the *mean* is cloned toward the labels on the states the recent rollouts visited (DAgger
                on the search's own distribution); the clone is evaluated beside the population on the
                same episodes and becomes the new mean when it beats every member (selection judges it:
                CEM-RL, Pourchot & Sigaud 2019; injected solutions, Hansen 2011)
``pair``        the same clone of the mean, as a direction: the next generation's first antithetic pair
                lies along ``theta* - mu`` (Meier et al. 2019)
==============  ==========================================================================================

The candidate's options (``shaping.mean_clone``): ``scales`` (candidates along ``theta* - mu``),
``accept`` (beat every member, or the mean), ``extra_episodes`` (also beat the mean on episodes nobody
was selected on), ``confirm`` (win again in the next generation).

A new mechanism is a :class:`Mechanism` subclass in its own file plus one entry in
``methods.MECHANISMS``. The guide calls, per generation: :meth:`Mechanism.background_job` (work overlapping the rollouts,
in the guide's shaping thread), :meth:`Mechanism.record_mask` (whose steps the rollouts keep),
:meth:`Mechanism.extra_members` (policies evaluated beside the population), :meth:`Mechanism.after_tell`
(after the ES update), and the state methods at every checkpoint.
"""

from __future__ import annotations

import numpy as np

CHECK_METRIC = "check_env_steps"  # candidate with check_episodes: the env steps of this generation's check (counted
#                                   in env_steps by the trainer, which imports this name from here, not candidate.py's
#                                   chain of Numba kernels; 0 where nothing won before the check)


class Mechanism:
    """Base of the label mechanisms: records everyone, evaluates nothing extra, has no state."""

    name = ""
    metric_keys: tuple[str, ...] = ()  # the metrics columns its after_tell fills
    extra_episodes = 0  # episodes its extra members run beyond the population's (after the common ones)
    probe_rows = False  # its extras are the label probe's candidate and the initial mean (generation 0)
    free_judgement = False  # its last judgement was that candidate's: a loss not held against the labels

    def __init__(self, host):
        self.host = host  # the ShapedGuide: cfg, spec, settings, data, labels, M_phi

    def record_mask(self, population: int, extra: int) -> np.ndarray:
        """Which members' steps the rollouts keep: ``(population + extra,)`` bool (default: all)."""
        return np.ones(population + extra, bool)

    def extra_members(self, generation: int) -> np.ndarray | None:
        """Policies ``(k, n)`` evaluated beside generation ``generation``'s population on its episodes."""
        return None

    def background_job(self, generation: int):
        """Work that may overlap generation ``generation``'s rollouts: a callable the guide runs in its
        shaping thread after M_phi's training steps (joined before ``after_tell``), or None. Prepared
        here, on the main thread: the job must read only what it is handed, not the guide's live data."""
        return None

    def after_tell(self, generation: int, params: np.ndarray, fitness: np.ndarray, extra_returns: np.ndarray,
                   results, old_mean: np.ndarray, strategy, map_tasks, judged=None) -> dict:
        """After ``strategy.tell``: ``params`` ``(P, n)`` the population, ``fitness`` ``(P,)`` its mean
        returns, ``extra_returns`` ``(k, E + x)`` the returns of :meth:`extra_members` on the
        population's E episodes and ``extra_episodes`` more; returns metrics.

        ``judged(metrics)`` (None: nobody asks): a mechanism whose slow work (a clone) neither changes
        the strategy nor the next generation's population may call it once, before that work, with the
        judgement's metrics (``candidate_accepted``, ``candidate_gain``); the next generation's
        population rollouts may then start while the work runs (the trainer's ``clone_overlap``)."""
        return {}

    def sleep(self) -> None:
        """The guide backs off (``guides/label_budget.py``): drop what was prepared for the next
        generation; the first generation after the sleep starts afresh."""

    def state_dict(self) -> dict[str, np.ndarray]:
        return {}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        pass


def every_kth(population: int, extra: int, k: int) -> np.ndarray:
    """Record mask ``(population + extra,)``: members ``0, k, 2k, ...`` of the population and every extra."""
    mask = np.zeros(population + extra, bool)
    mask[: population : max(1, int(k))] = True
    mask[population:] = True
    return mask
