"""What the shaped guide tells its label budget after each judged generation, and what the run then says: the
verdict (``guides/label_budget.py`` judges it), the sleep with its one note line (naming the threshold when the
run has already reached it), the next population's record mask once the verdict is in, and the warning when
M_phi has had no data for a while.

``LabelVerdicts`` is a part of ``guides/shaped.py``'s ``ShapedGuide`` (its base class), which owns the state these
methods use: ``budget``, ``mechanism``, ``cfg``, ``sh``, ``run_name``, ``has_controller``, ``_metrics_path`` and
``_warned``. Tested with the budget, in ``tests/guides/test_label_budget.py``.
"""

from __future__ import annotations

import sys

import numpy as np

from shaped_es.envs.thresholds import env_threshold
from shaped_es.rundir import metrics_csv

WARN_AFTER = 5  # generations without M_phi data before the console says so (once)


class LabelVerdicts:
    """The label budget's side of a :class:`~shaped_es.guides.shaped.ShapedGuide` (the module docstring names the
    guide's attributes these methods use)."""

    def _next_population_mask(self, population: int) -> np.ndarray:
        """The next generation's population record mask ``(population,)``, as its ``begin_generation`` and
        :meth:`record_mask` will give it (after this generation's verdict): none while asleep."""
        if not self.budget.awake:
            return np.zeros(population, bool)
        return self.mechanism.record_mask(population, 0)[:population]

    def _verdict(self, out: dict, fitness: np.ndarray) -> bool:
        """Tell the label budget whether this generation's candidate paid (``fitness``: the population's
        returns ``(P,)``); True: the labels keep losing, the guide sleeps from the next generation
        (:meth:`_sleep`, once the mechanism's work is done)."""
        if out.get("candidate_accepted") is None:
            return False
        if not out["candidate_accepted"] and self.mechanism.free_judgement:
            self.budget.free += 1  # the note's "won N of J" counts it, as the run line does
            return False  # the probe's candidate lost at generation 0: not held against the labels
        f = np.asarray(fitness, np.float64)  # (P,)
        return self.budget.judge(bool(out["candidate_accepted"]), out.get("candidate_gain"), float(f.mean()),
                                 reverted=bool(out.get("jump_reverted")), spread=float(f.max() - f.min()))

    def _sleep(self) -> None:
        """Asleep from the next generation: the mechanism drops what it prepared, with one warning line the
        first time."""
        self.mechanism.sleep()
        if self.budget.sleeps == 1:
            note = self.budget.note(self.cfg.env, self.has_controller, self.sh.labels, self._past_threshold())
            print(f"shaped-es: {self.run_name}: note: {note}", file=sys.stderr)

    def _past_threshold(self) -> tuple[float, float] | None:
        """(the best test reward the progress line reported so far, the env's threshold) when the env has a
        threshold and the run has reached it (a new user's blimp reached it at generation 7 and read the note
        at generation 40, its latest test just below, as a warning); else None. Read once, for the back-off note,
        from the rows metrics.csv holds now (a row whose test episodes are still running is not there yet)."""
        # the threshold the train command's line uses (the env's registered reward_threshold at these settings;
        # None: none, or not found), looked up here: only a run that sleeps needs it
        threshold = env_threshold(self.cfg)
        if threshold is None:
            return None
        try:
            rows = metrics_csv.read_table(self._metrics_path)[1]
            tests = [float(r["test_reward_mean"]) for r in rows if r.get("test_reward_mean") not in (None, "")]
        except Exception:  # noqa: BLE001 - unreadable: the note reads as it does without a threshold
            return None
        best = max((t for t in tests if np.isfinite(t)), default=None)
        if best is None or best < threshold[0]:
            return None
        return best, threshold[0]

    def _warn_untrained(self, generation: int) -> None:
        if self._warned or generation + 1 < WARN_AFTER:
            return
        self._warned = True
        mp = self.sh.inverse_dynamics
        print(f"shaped-es: {self.run_name}: warning: after {generation + 1} generations no episode passed M_phi's "
              f"filter (filter={mp.filter}, min_return={mp.min_return}): the shaped method runs as Vanilla-ES "
              f"until one does (column shaping_active = 0); --set shaping.inverse_dynamics.filter=none "
              f"keeps every transition", file=sys.stderr)
