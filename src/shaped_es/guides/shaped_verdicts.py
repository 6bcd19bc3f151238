"""How the shaped guide judges an awake generation, what it tells its label budget, and what the run then says:
the mechanism's judgement and clone (``_judge_and_clone``, the shaped part of ``after_tell``, with the
population's returns and the judged extras'), the verdict (``guides/label_budget.py`` judges it), the next
population's record mask once the verdict is in (the trainer's ``clone_overlap`` starts its rollouts then), the
probe candidate's line at generation 1 and the line at the first clone fitted under parameter noise, the sleep
with its one note line (naming the threshold when the run has already reached it), and the warning when M_phi
has had no data for a while.

``LabelVerdicts`` is a part of ``guides/shaped.py``'s ``ShapedGuide`` (its base class), which owns the state these
methods use: ``budget``, ``mechanism``, ``cfg``, ``sh``, ``placement``, ``search_sigma``, ``mean_clone_cfg``,
``_babblers``, ``_probe_res``, ``progress``, ``_noise_said``, ``run_name``, ``has_controller``, ``_metrics_path``
and ``_warned``. Tested with the budget, in ``tests/guides/test_label_budget.py``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from shaped_es.envs.thresholds import env_threshold
from shaped_es.guides.label_check import candidate_line
from shaped_es.guides.mechanisms.mean_clone import noise_line
from shaped_es.rollout import mean_returns
from shaped_es.rundir import metrics_csv

WARN_AFTER = 5  # generations without M_phi data before the console says so (once)


class LabelVerdicts:
    """The judgement and the label budget's side of a :class:`~shaped_es.guides.shaped.ShapedGuide` (the module
    docstring names the guide's attributes these methods use)."""

    def _judge_and_clone(self, out: dict, generation, params, results, old_mean, strategy, map_tasks,
                         ready=None) -> None:
        """The shaped part of an awake generation's ``after_tell`` (its arguments; ``out``: the generation's
        metrics so far, updated in place): the population's returns and the judged extras' handed to the
        mechanism, which judges and clones (``time_cloning_s``: less the time ``ready`` took); the verdict told
        to the label budget once the judgement is made (then ``ready(mask)``, master placement), the lines the
        run says, and the sleep the verdict calls for."""
        P = params.shape[0]
        fitness = mean_returns([r for r in results if r.members[0] < P])  # (P,) the population's
        # the mechanism's extras (k_i, E + x); the babblers come last, in tasks of their own, and are not judged
        k = sum(len(r.members) for r in results if r.members[0] >= P)
        extra = [np.asarray(r.returns) for r in results if P <= r.members[0] < P + k - self._babblers]
        extra_returns = np.concatenate(extra) if extra else np.zeros((0, self.cfg.rollout.episodes))
        verdict: list[bool] = []  # the label budget's, once judged: True = asleep from the next generation
        ready_s = [0.0]  # time spent starting the next rollouts (not cloning)

        def judged(metrics: dict) -> None:  # the judgement is made and the strategy final; the clone follows
            if verdict:
                return
            verdict.append(self._verdict(metrics, fitness))
            if ready is not None and self.placement == "master":
                t = time.perf_counter()
                ready(self._next_population_mask(P))
                ready_s[0] += time.perf_counter() - t

        self.search_sigma = strategy.search_scale()
        t0 = time.perf_counter()
        out.update(self.mechanism.after_tell(generation, params, fitness, extra_returns, results, old_mean,
                                             strategy, map_tasks, judged=judged))
        out["time_cloning_s"] = time.perf_counter() - t0 - ready_s[0]
        if self.mechanism.free_judgement:
            won = bool(out.get("candidate_accepted"))
            n = self.cfg.rollout.episodes + self.mean_clone_cfg.extra_episodes  # the paired episodes both ran
            judged_at = ((float(out["candidate_return"]), float(out["mean_return"]), float(np.max(fitness)),
                          float(out["candidate_gain"]), n)
                         if {"candidate_return", "mean_return", "candidate_gain"} <= set(out) else None)  # judged on
            print(f"shaped-es: {self.run_name}: generation 1: {candidate_line(self._probe_res, won, judged_at)}",
                  file=sys.stderr)
        if (out.get("clone_noise") or 0) > 0 and not self._noise_said:  # None: no clone this generation
            self._noise_said = True
            if self.progress:  # --quiet: not said (the same line in every run of a benchmark)
                print(f"shaped-es: {self.run_name}: generation {generation + 1}: {noise_line(self.mean_clone_cfg)}",
                      file=sys.stderr)
        if not verdict:  # the mechanism never judged early: judged on its metrics now
            verdict.append(self._verdict(out, fitness))
        if verdict[0]:
            self._sleep()

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
