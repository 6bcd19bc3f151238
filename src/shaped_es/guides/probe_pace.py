"""The label probe's progress lines (:class:`Pace`): a probe estimated to take longer than :data:`SAY_AFTER_S`
says, after its data, about how long the rest will take, and after each DAgger round of its simulated candidates,
how far it is; a short probe says nothing."""

from __future__ import annotations

import time

from shaped_es.guides.clone_probe import ROUNDS
from shaped_es.guides.probe_rollouts import EPISODES

SAY_AFTER_S = 20.0  # a probe estimated to take longer than this says how far it is (a slow simulator's run
#                     printed nothing for 6 minutes before generation 0: it looked hung)


class Pace:
    """Progress lines of a long probe: after its data, an estimate of the rest (from the data's own pace and
    episode length); after each DAgger round of the simulated candidates, how far it is. Silent where the
    estimate is below :data:`SAY_AFTER_S`, as for most of the built-in envs' 1-10 s probes; the estimate counts
    start-up, so it runs high, and such a probe can still print (a new user's CarNav-v0 probe on a busy machine,
    process executor: "at most about 24 s more", 3.7 s in all)."""

    def __init__(self, say, t0: float):
        self.say, self.t0, self.on = say, t0, False

    def after_data(self, steps: int, episodes: int, drives: int, sims: int, data_left: int = 0) -> None:
        """After ``episodes`` of the probe's data (``steps`` env steps; ``data_left`` more episodes of it to come):
        one line with the estimate, the first time it is over :data:`SAY_AFTER_S` (after the first of its data's
        generations already: a new user's slow base sat 26 s silent before the line after both)."""
        spent = time.perf_counter() - self.t0
        if self.say is None or self.on or steps <= 0 or episodes <= 0 or spent <= 0:
            return
        rest = (data_left + (drives + sims * ROUNDS) * EPISODES) * spent / episodes  # s, at the data's pace
        self.on = spent + rest > SAY_AFTER_S
        if self.on:
            self.say(f"label probe: {steps:,} env steps of babbling and members around the initial mean in "
                     f"{spent:.0f} s; at most about {rest:.0f} s more before generation 1 (at the pace of its first "
                     f"episodes, start-up included; the labels of {drives - 1} "
                     f"variants drive {EPISODES} episodes each, then {sims} candidates are cloned and driven over "
                     f"{ROUNDS} DAgger rounds; once per run, kept in label_probe.json)")

    def after_round(self, r: int) -> None:
        if self.on:
            self.say(f"label probe: DAgger round {r + 1} of {ROUNDS} done ({time.perf_counter() - self.t0:.0f} s)")
