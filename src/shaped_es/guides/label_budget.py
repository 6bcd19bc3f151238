"""When the labels keep losing, the shaped run stops paying for them (and tries again later).

A candidate mechanism's labels pay only through accepted candidates. Each generation where a candidate
was judged (its returns compared with the population's) is a *judgement*; ``patience`` judgements in a
row without an acceptance put the guide to sleep: for ``sleep`` generations it records no steps, trains
no ``M_phi``, evaluates no candidate or babbler and clones nothing -- the generation is Vanilla-ES's, at
Vanilla-ES's price. Then it wakes: one generation to record and clone, then ``WAKE_JUDGED`` judgements;
an acceptance keeps it awake (and resets the sleep to ``first_sleep``), none sends it back to sleep for
twice as long (at most ``max_sleep``): an exponential back-off, the schedule a retrying client uses.
With ``keep_rate`` (off by default), while the run's labels have paid their share (``keep_rate`` of the
judged generations accepted, and at least ``KEEP_MIN_WINS``), a losing trial does not double the sleep:
labels that won early often win again later (the kart: 3 wins in its first 5 judgements, a 32-generation
sleep, then 5 wins in 13 once awake), and two losses are no evidence against a 1-in-3 win rate. Measured
at 0.2 (``docs/benchmarks/backoff_keep_v9``): more candidates accepted late, the same generations to the
threshold on the suite and four held-out bodies, and 5-43% more awake generations: the labels' wins that
move a run come early.

With ``judge_jumps``, an acceptance is judged once more, by what followed it: if the next generation's
population (sampled around the accepted candidate) has a lower mean return than the population before the
jump, the jump counts as a lost judgement after all (the streak it reset is restored, plus one). A
candidate can beat the old mean on its episodes and still land where the search does worse: on
UR5Reach-v0 (the suite's default study) the population's mean return rose after 37% of accepted jumps
against 62% after the other judged generations, on the points and CarNav-v0 after 67-81% against 50-57%.

With ``heavy`` (H), a run whose labels have never won sleeps early, before ``patience``, once at least
:data:`HEAVY_MIN` judgements in a row lost by a median of more than H times the population's spread of returns
(its best member's return minus its worst's): its candidates are typically worse than everything the search
sampled around the mean, which no close-call loss is. The median spares a run whose first candidate, cloned
toward freshly trained labels, lost badly and whose later ones lose narrowly (the Reacher's seed 13). Only the
first sleep comes early, and it is twice the first sleep: such a streak is the evidence a lost wake-up trial is;
the wake-up trials are as above. Measured (``docs/benchmarks/backoff_heavy_v12``, ``backoff_heavy_v13``): a
replay of the 160 committed suite and held-out runs' judgements finds it changes only the swimmer's never-paying
runs (with 4 losses or 3, a first sleep of 4 or 8); counting each heavy loss twice instead (the first versions)
also changed that Reacher seed (21 generations slower) or, counted after a first win too, late streaks of paying
runs.

So a run whose labels never pay spends, after its first ``patience`` judgements, at most about
``(1 + WAKE_JUDGED) / (1 + WAKE_JUDGED + max_sleep)`` of its generations on shaping. State is a few
integers, saved in the checkpoint (resume is exact).
"""

from __future__ import annotations

import numpy as np

WAKE_JUDGED = 2  # judgements a woken guide gets to show a win before it sleeps again
HEAVY_MIN = 3  # losses in a row before their median can put a never-winning guide to sleep early (heavy)
FIRST_SLEEP = 4  # generations of the first sleep
KEEP_MIN_WINS = 2  # acceptances before keep_rate holds the sleep (one can be luck: a noise env wins 1 of its first 4)


class LabelBudget:
    """Counts judgements and acceptances; decides whether a generation is shaped (:attr:`awake`)."""

    def __init__(self, patience: int, max_sleep: int, first_sleep: int = FIRST_SLEEP, judge_jumps: bool = False,
                 keep_rate: float = 0.0, heavy: float = 0.0):
        self.patience, self.max_sleep, self.judge_jumps = int(patience), int(max_sleep), bool(judge_jumps)
        self.keep_rate = float(keep_rate)  # a share of accepted judgements at which sleeps stop doubling
        self.heavy = float(heavy)  # median loss, in population spreads, that sleeps a never-won run early (0: off)
        self.first_sleep = max(1, min(int(first_sleep), self.max_sleep)) if self.max_sleep else 0
        self.losses = 0  # judgements in a row without an acceptance
        self.spreads: list[float] = []  # this streak's losses in population spreads (heavy; -gain / spread)
        self.sleep = self.first_sleep  # the next sleep's length
        self.asleep_left = 0  # generations of the current sleep still to come
        self.trial = 0  # judgements left in a wake-up trial (0: not in a trial)
        self.sleeps = 0  # sleeps begun (the guide warns at the first)
        self.silent = 0  # generations slept through
        self.judged = 0
        # judgements not held against the labels (generation 0's probe candidate that lost): counted only in the
        # note's "won N of J", as the run line and the final JSON count every judged generation
        self.free = 0
        self.accepted = 0
        self.undone = 0  # accepted jumps the next generation undid (counted in accepted too; the note says so)
        self.gain_sum = 0.0
        self.streak_before = 0  # the losses in a row the last acceptance reset (judge_jumps restores them)
        self.prev_accepted = 0  # the last judgement was an acceptance
        self.prev_population = 0.0  # the last judged generation's population mean return (read if prev_accepted)

    @property
    def enabled(self) -> bool:
        return self.patience > 0 and self.max_sleep > 0

    @property
    def awake(self) -> bool:
        return self.asleep_left == 0

    def begin(self) -> bool:
        """Called at the start of a generation; True when it is shaped."""
        if self.asleep_left:
            self.asleep_left -= 1
            self.silent += 1
            if self.asleep_left == 0:
                self.trial = WAKE_JUDGED  # wakes after this generation, on trial
            self.prev_accepted = 0
            return False
        return True

    def judge(self, accepted: bool, gain: float | None, population: float | None = None,
              reverted: bool = False, spread: float | None = None) -> bool:
        """Record one judgement; True when it puts the guide to sleep (from the next generation).
        ``population``: this generation's population mean return (``judge_jumps``); ``reverted``: this
        generation undid the last one's jump (the candidate's ``revert_margin``), which then counts as lost;
        ``spread``: the population's best return minus its worst (``heavy``)."""
        self.judged += 1
        self.accepted += int(accepted)
        self.undone += int(reverted)
        if gain is not None and np.isfinite(gain):
            self.gain_sum += float(gain)
        if reverted or (self.judge_jumps and population is not None and self.prev_accepted
                        and population < self.prev_population):  # the population fell after the last jump
            self.losses = self.streak_before + 1
        self.prev_population = 0.0 if population is None else float(population)
        self.prev_accepted = int(accepted and population is not None)
        if accepted:
            self.streak_before = self.losses
            self.losses, self.trial, self.sleep, self.spreads = 0, 0, self.first_sleep, []
            return False
        self.losses += 1
        if (self._first_streak() and gain is not None and spread is not None and np.isfinite(gain)
                and np.isfinite(spread) and spread > 0):
            self.spreads.append(-float(gain) / float(spread))
        if not self.enabled:
            return False
        early = not self.trial and self.losses < self.patience  # before the patience: only the heavy rule sleeps
        if self.trial:
            self.trial -= 1
            if self.trial:
                return False
        elif early and not self.heavy_streak():
            return False
        if early:  # a heavy streak is the evidence a failed wake-up trial is: its first sleep starts doubled
            self.sleep = min(2 * self.sleep, self.max_sleep)
        self.asleep_left, self.trial, self.sleeps = self.sleep, 0, self.sleeps + 1
        if not (self.keep_rate and self.accepted >= max(KEEP_MIN_WINS, self.keep_rate * self.judged)):
            self.sleep = min(2 * self.sleep, self.max_sleep)
        return True

    def _first_streak(self) -> bool:
        """The heavy rule applies: on, the labels never won, the guide never slept."""
        return self.heavy > 0 and self.accepted == 0 and self.sleeps == 0

    def heavy_streak(self) -> bool:
        """A never-winning guide's first streak lost by a median of more than ``heavy`` spreads (module
        docstring): it sleeps without waiting for ``patience``."""
        return bool(self._first_streak() and len(self.spreads) >= HEAVY_MIN
                    and float(np.median(self.spreads)) > self.heavy)

    def note(self, env: str, has_controller: bool, labels: str = "mphi",
             past: tuple[float, float] | None = None) -> str:
        """The line a run prints when it first sleeps: what happened, what sleeping costs, what to try (the env's
        controller labels only where ``has_controller`` and the run's ``labels`` are M_phi's: a new user's
        controller-label run was told to try the controller's labels); README.md's back-off ("backs off") says
        more. ``past``: (the run's best test reward so far, the env's reward threshold) when that reward is at or
        above the threshold: the line says so instead of advice (a new user read the note on a run already past
        the threshold as a warning)."""
        oracle = "--set shaping.labels=controller, " if has_controller and labels == "mphi" else ""
        n = min(self.losses, self.patience) or self.patience
        far = (f" by a median of {np.median(self.spreads):.1f} population spreads" if n < self.patience
               and self.spreads else "")
        # a jump the next generation undid (revert_paired) is a win the run did not keep
        won = (f"won {self.accepted} of {self.judged + self.free}, {self.undone} undone" if self.undone else
               f"won {self.accepted} of {self.judged + self.free} so far")
        head = (f"labels lost {n} judged generations in a row{far} ({won}): "
                f"shaping sleeps {self.asleep_left} generations at the ES strategy's price and retries (metrics.csv "
                f"shaping_awake)")
        # after a win ("won N of J" says how many): the advice is for a run that stalls. Two new users' runs (a
        # drone, a 3-link arm) read the older "they paid before: the search may now outpace them" as all is well
        # where they had stalled below zero action's return
        if past is not None and past[0] >= past[1]:  # solved: the search outpaces the labels, as it should
            return head + (f"; the run has reached {env}'s reward threshold {past[1]:g} (best test reward "
                           f"{past[0]:.2f}): the labels' candidates no longer beat the search and sleeping saves "
                           f"their price (nothing to fix)")
        once = "if it stalls, " if self.accepted else ""
        if labels != "mphi":  # check-env --labels probes M_phi's labels, not these
            return head + f"; {once}compare --method vanilla / cmaes"
        return head + f"; {once}try shaped-es check-env {env} --labels; compare {oracle}--method vanilla / cmaes"

    def summary(self) -> dict:
        """What shaping did so far (the final JSON's ``shaping``, with ``accepted_then_fell``, is
        :func:`rows_summary`'s, read from metrics.csv)."""
        return {"candidates_judged": self.judged, "candidates_accepted": self.accepted,
                "mean_gain": self.gain_sum / self.judged if self.judged else None,
                "generations_backed_off": self.silent, "asleep": not self.awake}

    _FIELDS = ("losses", "sleep", "asleep_left", "trial", "sleeps", "silent", "judged", "accepted",
               "streak_before", "prev_accepted")
    _OLD = 8  # counters of a checkpoint from before judge_jumps (the rest start at 0)
    _FELL = 11  # counters of a checkpoint that also counted accepted_then_fell (the last, now dropped)

    def state_dict(self) -> dict[str, np.ndarray]:
        return {"ints": np.array([getattr(self, f) for f in self._FIELDS], np.int64),
                "spreads": np.array(self.spreads, np.float64),
                "gain_sum": np.array([self.gain_sum], np.float64),
                "prev_population": np.array([self.prev_population], np.float64),
                "free": np.array([self.free], np.int64), "undone": np.array([self.undone], np.int64)}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        if "ints" not in state:  # a checkpoint from before the budget: start counting now
            return
        ints = np.asarray(state["ints"], np.int64).reshape(-1)
        if ints.size not in (self._OLD, len(self._FIELDS), self._FELL) or (ints < 0).any():
            raise ValueError(f"label budget state has {ints.size} counters (expected {len(self._FIELDS)}, "
                             f"none negative)")
        ints = ints[: len(self._FIELDS)]
        for f, v in zip(self._FIELDS, np.pad(ints, (0, len(self._FIELDS) - ints.size))):
            setattr(self, f, int(v))
        self.gain_sum = float(np.asarray(state.get("gain_sum", [0.0]), np.float64).reshape(-1)[0])
        self.spreads = [float(v) for v in np.asarray(state.get("spreads", np.zeros(0)), np.float64).reshape(-1)]
        self.prev_population = float(np.asarray(state.get("prev_population", [0.0]), np.float64).reshape(-1)[0])
        self.free = int(np.asarray(state.get("free", [0]), np.int64).reshape(-1)[0])
        self.undone = int(np.asarray(state.get("undone", [0]), np.int64).reshape(-1)[0])  # 0: an older checkpoint


def never_accepted(summary: dict | None, base: str | None, short: bool = False) -> str | None:
    """The line a run prints at its end when its labels never paid (``summary``: :func:`rows_summary`'s): no
    candidate accepted, so the search took its ES strategy's own steps, those of the method ``base`` (the
    run method's ``methods.Method.base``); None when one was, or none judged. ``short``: the few words a
    benchmark's line for the run ends with."""
    if not summary or not summary["candidates_judged"] or summary["candidates_accepted"]:
        return None
    cost = summary.get("cost")
    if short:
        who = f"{base}'s" if base else "the ES strategy's"
        return f"no candidate accepted in {_judged(summary)}: {who} own steps" + (
            f" (shaping about {cost['seconds']:.0f} s of {cost['run_s']:.0f} s)"
            if cost and cost.get("run_s") is not None else "")
    head = f"no candidate was accepted in {_judged(summary)}: the search took "
    cost = cost_words(cost)
    if base is None:
        return head + "its ES strategy's own steps" + cost
    return head + (f"{base}'s own steps (--method {base}, same seed: the same policies, without shaping's "
                   f"probe and awake generations){cost}")


def shaping_line(summary: dict | None, generations: int) -> str | None:
    """The line a run prints at its end when candidates were accepted (``summary``: :func:`rows_summary`'s): how
    many of the judged, how many the next generation undid, the mean gain, the generations backed off (a new user
    found these only in the final JSON and the report); None where :func:`never_accepted` speaks, or none judged."""
    if not summary or not summary["candidates_judged"] or not summary["candidates_accepted"]:
        return None
    undone = summary.get("jumps_reverted") or 0
    gain = summary.get("mean_gain")
    return (f"shaping: {summary['candidates_accepted']} of {summary['candidates_judged']} judged candidates accepted"
            + by_source(summary) + (f" ({undone} undone by the next generation)" if undone else "")
            + (f", mean gain {gain:+.2f} over the mean's return (every judged one's, the lost too)"
               if gain is not None else "")
            + f"; backed off {summary['generations_backed_off']} of {generations} generations (metrics.csv "
              f"candidate_*, shaping_awake; shaped-es report RUN_DIR compares runs)")


# where an accepted candidate came from: rows_summary's key, the metrics.csv candidate_rival values it counts (5: the
# label probe's candidate at generation 0, mechanisms/candidate.PROBE; the rivals' variants, guides/rival.py: shoot_base
# also the third horizon's, 6, and a fourth's, 7, in the runs of commit 2dd35906, measured and removed) and the name
# shaping_line gives it; the rest of the accepted are the run's own labels'
SOURCES = (("accepted_probe", (5,), "the probe's"), ("accepted_rival", (1,), "frame rival"),
           ("accepted_servo", (2,), "servo"), ("accepted_shoot", (3,), "shooting"),
           ("accepted_shoot_base", (4, 6, 7), "shooting, other horizons"),
           ("accepted_shoot_hold", (8,), "held-goal shooting"))


def by_source(summary: dict) -> str:
    """`` (own labels 2, shooting 1, held-goal shooting 3)``: whose clone the accepted candidates were, where one came
    from anything but the run's own labels (a new user could not tell from the printed lines whether an option's
    rival had won); empty otherwise."""
    counts = [(name, int(summary.get(key) or 0)) for key, _, name in SOURCES]
    own = int(summary["candidates_accepted"]) - sum(n for _, n in counts)
    if not any(n for _, n in counts):
        return ""
    return " (" + ", ".join(f"{name} {n}" for name, n in [("own labels", own), *counts] if n) + ")"


def _num(v) -> float | None:
    try:
        x = float(v)
    except (TypeError, ValueError):
        return None
    return x if np.isfinite(x) else None


def rows_summary(rows: list[dict]) -> dict | None:
    """What shaping did over a run's metrics rows (None: no candidate columns, not a candidate run):
    candidates judged and accepted (and with check_episodes, ``check_lost``: winners on the judged episodes
    that lost the check), their mean return gain, acceptances after which the population's mean
    return (``train_reward_mean``) fell (the jumps :meth:`LabelBudget.judge` counts as lost with
    ``judge_jumps``), generations backed off; with rivals, how many accepted were each one's clone."""
    if not rows or "candidate_accepted" not in rows[0]:
        return None
    acc = [a for a in (_num(r.get("candidate_accepted")) for r in rows) if a is not None]
    gains = [g for g in (_num(r.get("candidate_gain")) for r in rows) if g is not None]
    asleep = sum(1 for r in rows if _num(r.get("shaping_awake")) == 0)
    fell, prev_accepted, prev_pop = 0, False, 0.0
    for r in rows:
        a, pop = _num(r.get("candidate_accepted")), _num(r.get("train_reward_mean"))
        if _num(r.get("shaping_awake")) == 0:
            prev_accepted = False
        if a is None:
            continue
        fell += int(prev_accepted and pop is not None and pop < prev_pop)
        prev_accepted, prev_pop = bool(a) and pop is not None, pop if pop is not None else 0.0
    out = {"candidates_judged": len(acc), "candidates_accepted": int(sum(acc)),
           "mean_gain": float(np.mean(gains)) if gains else None, "accepted_then_fell": fell,
           "generations_backed_off": asleep}
    if "check_env_steps" in rows[0]:  # check_episodes: winners the check's episodes did not bear out
        out["check_lost"] = sum(1 for r in rows if (_num(r.get("check_env_steps")) or 0) > 0
                                and _num(r.get("candidate_accepted")) == 0)
    if "jump_reverted" in rows[0]:  # revert_paired / revert_margin: jumps the next generation undid
        out["jumps_reverted"] = sum(1 for r in rows if _num(r.get("jump_reverted")) == 1)
    # the accepted per source (SOURCES): the label probe's candidate wherever candidate_rival is logged; a rival's
    # (guides/rival.py) None where the run had no such rival (no gain column of it)
    head = rows[0]
    has = {"accepted_probe": "candidate_rival" in head,
           "accepted_rival": "candidate_rival" in head and ("rival_gain" in head or "servo_gain" not in head),
           "accepted_servo": "servo_gain" in head, "accepted_shoot": "shoot_gain" in head,  # older runs: candidate_rival
           "accepted_shoot_base": "shoot_base_gain" in head, "accepted_shoot_hold": "shoot_hold_gain" in head}  # alone
    for key, vs, _ in SOURCES:
        if has[key] or key != "accepted_probe":  # a run without the column has no probe count at all
            out[key] = sum(1 for r in rows if _num(r.get("candidate_accepted")) == 1
                           and _num(r.get("candidate_rival")) in vs) if has[key] else None
    return out


MIN_SLEPT = 3  # generations shaping slept through before their median prices a generation without it


def cost_summary(rows: list[dict], probe_s: float) -> dict | None:
    """About what shaping cost a run in wall time: the label probe's seconds (``probe_s``) plus each awake
    generation's seconds (``gen_time_s``) beyond the median of the generations it slept through, which are the ES
    strategy's own, priced on this machine in this run; None with fewer than :data:`MIN_SLEPT` of those (no price
    to compare with). Machine noise enters both sides: a rough figure, said as one ("about")."""
    slept = [t for r in rows if _num(r.get("shaping_awake")) == 0 and (t := _num(r.get("gen_time_s"))) is not None]
    if len(slept) < MIN_SLEPT:
        return None
    price = float(np.median(slept))
    awake = [t for r in rows if _num(r.get("shaping_awake")) == 1 and (t := _num(r.get("gen_time_s"))) is not None]
    run_s = _num(rows[-1].get("wall_time_s"))
    return {"seconds": round(probe_s + sum(max(0.0, t - price) for t in awake), 1), "probe_s": round(probe_s, 1),
            "awake_generations": len(awake), "run_s": None if run_s is None else round(run_s, 1)}


def run_cost(rows: list[dict], root) -> dict | None:
    """:func:`cost_summary` of the run in folder ``root`` (its probe's seconds from ``RUN/label_probe.json``)."""
    from shaped_es.guides.probe_file import seconds_in

    return cost_summary(rows, seconds_in(root))


def cost_words(cost: dict | None) -> str:
    """``; shaping cost about 9 s of the run's 28 s: ...`` from :func:`cost_summary` ("" without one)."""
    if not cost or cost.get("run_s") is None:
        return ""
    n = cost["awake_generations"]
    return (f"; shaping cost about {cost['seconds']:.0f} s of the run's {cost['run_s']:.0f} s: the label probe's "
            f"{cost['probe_s']:.1f} s and what its {n} awake generation{'s' * (n != 1)} took beyond a slept one's")


def _judged(summary: dict) -> str:
    """``12 judged generations`` (``1 judged generation``)."""
    n = summary["candidates_judged"]
    return f"{n} judged generation{'s' * (n != 1)}"
