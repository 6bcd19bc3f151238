"""``shaping.mechanism = candidate``: the mean's clone as a candidate that selection judges.

Per generation ``g`` (the search's mean ``mu_g``):

1. ``c_g = mu_g + s (theta*_g - mu_g)`` for each scale ``s`` (``mean_clone.scales``; ``theta*_g`` the
   mean's clone, ``mean_clone.py``, taken after the previous generation's update; with ``warm_start``
   the clone continues from the previous clone instead of starting at the mean: a DAgger learner kept
   across generations, cheaper to keep fitted), and ``mu_g`` itself, are rolled out beside the
   population, on the same episode seeds (common random numbers);
2. the ES update gives ``mu_{g+1}``; the best ``c_g`` **replaces** it if its return beats every
   member's (``accept = best``; or the mean's own, ``accept = mean``) -- a jump no ES step of the
   Adam-normalized size can make, taken only where the returns say it pays. With ``extra_episodes``
   the candidates and the mean also run that many episodes nobody was selected on, and a winner must
   beat the mean there too (a return on two episodes can be luck). With ``confirm`` the
   winner is first evaluated again beside the next generation, on new episodes, and the jump is taken
   only if it beats the mean's return there (UR5Reach-v0: winners on two lucky episodes, accepted at
   once, led the mean into colliding regions; waiting a generation before each jump cost CarNav-v0 its
   speed: ``docs/benchmarks/labels_ur5``). With ``revert_paired`` a jump is judged once more, against what
   it replaced: the mean the ES step alone gave (``mu_{g+1}``, kept as ``undo``) runs beside the next generation
   on the mean's episodes, and the jump is undone if that mean beats the jumped one by the paired test at that
   margin (the candidate beat ``mu_g``; where the ES step is productive, ``mu_{g+1}`` is already past it);
3. the new mean is cloned again for the next generation.

Cloning toward perfect labels on a member's own states lowers its return (compounding error), and a
surrogate subspace spanned by clones is mostly the generation's own perturbations (issue #19); judging
the clone by its return instead, and aggregating the states the clones themselves visit (DAgger), is
what lets labels move the search. Cost: ``len(scales) + 1`` more members' episodes and one clone.
Logged: ``candidate_return``, ``mean_return``, ``candidate_gain`` (their difference: the return change
the labels made), ``candidate_accepted``, ``candidate_scale``, ``clone_step_update_cosine`` (the label
direction ``theta* - mu_g`` against the ES update).
"""

from __future__ import annotations


import numpy as np

from shaped_es import seeding
from shaped_es.guides.concurrent import concurrently
from shaped_es.guides.mechanisms import CHECK_METRIC, Mechanism, every_kth
from shaped_es.guides.mechanisms.mean_clone import CLONE_KEY, clone_mean
from shaped_es.rollout import population_tasks, run_task
from shaped_es.shaping.surrogate import cosine

CLONE_METRICS = ("clone_loss_before", "clone_loss_after", "label_std", "clone_samples",
                 "clone_noise")  # the parameter noise the clone was fitted under (mean_clone.noise * es.sigma; 0 before noise_from)
RIVAL_METRICS = ("candidate_rival",)  # with rival label variants (guides/rival.py): the winning row's variant
GAIN_METRIC = {1: "rival_gain", 2: "servo_gain", 3: "shoot_gain", 4: "shoot_base_gain", 6: "shoot_third_gain",
               8: "shoot_hold_gain"}  # per variant: its
#                                                              candidate's gain over the mean
PROBE = 5  # candidate_rival at generation 0: the label probe's best simulated candidate (guides/probe_candidate.py)
SUBSAMPLE_KEY = 1_000_025  # seed key of a costly rival's row subsample
REVERT_METRIC = "jump_reverted"  # with revert_margin / revert_paired: 1 where this generation undid the last one's jump
UNDO_METRIC = "undo_gain"  # with revert_paired: the ES step's own mean's return minus the jumped mean's (a jump's
#                            next generation; NaN elsewhere)


def population_fell(now: np.ndarray, before: tuple[float, float, int], margin: float) -> bool:
    """The population's mean return ``now`` ``(P,)`` is below ``before`` (the earlier population's mean,
    variance and size) by more than ``margin`` standard errors of the difference of two means."""
    f = np.asarray(now, np.float64)  # (P,)
    m0, v0, n0 = before
    if f.size < 2 or n0 < 2:
        return False
    se = np.sqrt(f.var(ddof=1) / f.size + v0 / n0)
    return bool(f.mean() < m0 - margin * se)


def rival_clone_key(variant: int) -> int:
    """The seed key of a rival variant's clone (variant 1's is the one it always had)."""
    return CLONE_KEY + variant


def _learner_key(variant: int) -> str:
    return "rival_learner" if variant == 1 else f"rival_learner_{variant}"


def paired_win(cand: np.ndarray, mean: np.ndarray, margin: float = 1.0) -> bool:
    """The candidate beats the mean on the same episodes (common random numbers) by more than ``margin``
    standard errors of the paired differences ``cand_e - mean_e`` (one: a one-sided test at about 84%; on
    two episodes a win is often luck where episodes differ)."""
    d = np.asarray(cand, np.float64) - np.asarray(mean, np.float64)  # (E + x,)
    if d.size < 2:
        return bool(d.size and d[0] > 0)
    return bool(d.mean() > margin * d.std(ddof=1) / np.sqrt(d.size))


def flat_win(fitness: np.ndarray, cand: np.ndarray, mean: np.ndarray) -> bool:
    """Every member of the population returned the same (a plateau; a sparse reward nobody met yet: the ES
    step has no signal to follow) and the candidate gains over the mean on average: the only way off it.
    One success among n episodes never passes :func:`paired_win`: x / n is exactly its own standard error."""
    f = np.asarray(fitness, np.float64)  # (P,)
    return bool(f.size and np.ptp(f) == 0.0 and np.mean(np.asarray(cand, np.float64) - mean) > 0)


class MeanCandidate(Mechanism):
    name = "candidate"
    metric_keys = ("candidate_return", "mean_return", "candidate_gain", "candidate_accepted",
                   "candidate_scale", "clone_step_update_cosine") + CLONE_METRICS

    def __init__(self, host):
        super().__init__(host)
        self.cfg = host.mean_clone_cfg
        self.extra_episodes = self.cfg.extra_episodes
        self.extras: np.ndarray | None = None  # (k, n) float32: the candidates, [the pending one,] the mean
        self.pending = 0  # 1: the row before the mean is held from the last generation (confirm: its winner)
        self.learner: np.ndarray | None = None  # warm_start: the last clone, where the next one starts
        self.jumped = False  # the last generation's new mean was an accepted candidate (keep_step_repeat)
        self.rivals: list[int] = []  # the variants of the rows after the scaled candidates (guides/rival.py)
        self.rival_learners: dict[int, np.ndarray] = {}  # warm_start: each rival's last clone
        # revert_margin: the mean the ES step alone gave when the last generation jumped (None: no jump to
        # judge), and the last judged population's return mean, variance and size (the jump's yardstick)
        self.undo: np.ndarray | None = None
        self.prev_pop: tuple[float, float, int] = (0.0, 0.0, 0)
        self.undo_row = 0  # revert_paired: 1 where the row before the mean is ``undo`` (the ES step's mean)
        self.reverts = self.cfg.revert_margin > 0 or self.cfg.revert_paired > 0
        known = [r.variant for r in getattr(host, "rivals", [])]
        self.unrecorded = {r.variant for r in getattr(host, "rivals", []) if not getattr(r, "records", True)}
        if known:
            self.metric_keys = self.metric_keys + RIVAL_METRICS + tuple(GAIN_METRIC[v] for v in known)
        if self.reverts:
            self.metric_keys = self.metric_keys + (REVERT_METRIC,)
        if self.cfg.revert_paired > 0:
            self.metric_keys = self.metric_keys + (UNDO_METRIC,)
        if self.cfg.check_episodes and not self.cfg.confirm:
            self.metric_keys = self.metric_keys + (CHECK_METRIC,)
        # the label probe's best simulated candidate, judged beside generation 0 (guides/probe_candidate.py)
        first = getattr(host, "probe_candidate", None)
        if first is not None and self.cfg.probe_candidate:
            x0 = seeding.initial_mean(host.spec, host.cfg.seed)  # the trainer's initial mean
            self.extras = np.stack([first, x0]).astype(np.float32)  # (2, n): the candidate, the mean
            self.probe_rows = True

    def record_mask(self, population: int, extra: int) -> np.ndarray:
        mask = every_kth(population, extra, self.cfg.record_every)
        if self.probe_rows:  # M_phi's data as without them: a losing probe candidate changes nothing else
            mask[population:population + 2] = False
        if self.undo_row and self.extras is not None:  # revert_paired's row: M_phi's data as without it
            mask[population + self.extras.shape[0] - 2] = False
        if self.extras is not None:  # a rival whose candidate is not recorded (rival.Rival.records): data as without it
            ns = len(self.cfg.scales)
            for i, v in enumerate(self.rivals):
                if v in self.unrecorded:
                    mask[population + ns + i] = False
        return mask

    def extra_members(self, generation: int) -> np.ndarray | None:
        return self.extras

    def after_tell(self, generation, params, fitness, extra_returns, results, old_mean, strategy,
                   map_tasks, judged=None) -> dict:
        out: dict = {}
        self.free_judgement, self.probe_rows = self.probe_rows, False
        held = None  # a row for the next generation: the winner to confirm
        jumped, self.jumped = self.jumped, False  # the last generation's, and this one's (set on a jump)
        # revert_margin: the population just rolled out was sampled around the last generation's jump; if it
        # does clearly worse than the one before the jump, the jump's neighbourhood is worse than the old
        # mean's (a clone can beat the mean as one policy on a few episodes and still sit where the search,
        # which climbs the Gaussian-smoothed return, does worse): back to the ES step's mean, which this
        # generation's candidates (cloned around the jump) do not replace
        undo, self.undo = self.undo, None
        undo_row, self.undo_row = self.undo_row, 0
        rows_ok = self.extras is not None and extra_returns.shape[0] == self.extras.shape[0]
        reverted = undo is not None and (
            (self.cfg.revert_margin > 0 and population_fell(fitness, self.prev_pop, self.cfg.revert_margin))
            # revert_paired: the ES step's own mean (the row before the mean) against the jumped mean, paired
            or bool(undo_row and rows_ok and paired_win(extra_returns[-2], extra_returns[-1], self.cfg.revert_paired)))
        if reverted:
            strategy.set_mean(undo)
            jumped = False
        elif self.cfg.revert_margin > 0:
            f = np.asarray(fitness, np.float64)  # (P,)
            self.prev_pop = (float(f.mean()), float(f.var(ddof=1)) if f.size > 1 else 0.0, int(f.size))
        if self.reverts:
            out[REVERT_METRIC] = int(reverted)
        if undo_row and rows_ok:
            out[UNDO_METRIC] = float(np.mean(extra_returns[-2] - extra_returns[-1]))
        if rows_ok:
            E = self.host.cfg.rollout.episodes
            common = extra_returns[:, :E].mean(axis=1)  # (k,) on the population's episodes
            # with extra_episodes: the candidates must also beat the mean on episodes nobody was chosen on
            more = extra_returns[:, E:].mean(axis=1) if extra_returns.shape[1] > E else None  # (k,)
            k = self.extras.shape[0] - 1 - self.pending - undo_row  # this generation's new candidates (scales, rivals)
            f_cand, f_mean = common[:k], float(common[-1])  # (k,), the mean's
            # the candidate tested: the best on the common episodes, or (pick_all) on every episode they ran
            j = int(np.argmax(extra_returns[:k].mean(axis=1) if self.cfg.pick_all else f_cand))
            bar = float(np.max(fitness)) if self.cfg.accept in ("best", "best_paired") else f_mean

            def flat(i: int) -> bool:
                return bool(self.cfg.accept_flat and flat_win(fitness, extra_returns[i], extra_returns[-1]))

            def passes(i: int, over: float) -> bool:
                z = self.cfg.accept_margin
                if flat(i):
                    return True
                if self.cfg.accept == "paired":
                    if self.cfg.accept_fresh and more is not None:  # the episodes the pick did not see
                        return paired_win(extra_returns[i, E:], extra_returns[-1, E:], z)
                    return paired_win(extra_returns[i], extra_returns[-1], z)
                if self.cfg.accept == "best_paired" and not paired_win(extra_returns[i], extra_returns[-1], z):
                    return False
                return bool(common[i] > over and (more is None or more[i] > more[-1]))
            won = passes(j, bar)
            if self.free_judgement:  # the probe's candidate must also beat every member (probe_candidate.py)
                won = won and bool(f_cand[j] > np.max(fitness))
            if CHECK_METRIC in self.metric_keys:
                out[CHECK_METRIC] = 0
            if won and self.cfg.check_episodes and not self.cfg.confirm and not reverted and not flat(j):
                won, out[CHECK_METRIC] = self._check(generation, j, extra_returns, map_tasks)
            # the held row (last generation's winner, confirm): it must beat the new mean's return on new episodes
            confirmed = bool(self.pending) and self.cfg.confirm and passes(k, f_mean) and not reverted
            accept = not reverted and (confirmed or (won and not self.cfg.confirm))
            es_update = np.asarray(strategy.mean, np.float64) - np.asarray(old_mean, np.float64)  # (n,)
            gain = float(np.mean(extra_returns[j] - extra_returns[-1]))  # over every episode both ran
            ns = len(self.cfg.scales)  # the rivals' rows, if any, follow the scaled candidates
            out.update(candidate_return=float(f_cand[j]), mean_return=f_mean, candidate_gain=gain, candidate_accepted=int(accept),
                       candidate_scale=float(self.cfg.scales[j]) if j < ns else 1.0,
                       clone_step_update_cosine=cosine(self.extras[0] - self.extras[-1], es_update))
            if self.free_judgement and RIVAL_METRICS[0] in self.metric_keys:  # no label source's row this time
                out["candidate_rival"] = PROBE
            if self.rivals:
                out["candidate_rival"] = self.rivals[j - ns] if j >= ns else 0
                for i, v in enumerate(self.rivals):
                    out[GAIN_METRIC[v]] = float(np.mean(extra_returns[ns + i] - extra_returns[-1]))
            if accept:  # selection prefers the label-made policy to anything ES sampled: jump there
                jump = np.asarray(self.extras[k] if confirmed else self.extras[j], np.float64)  # (n,)
                # keep_step: the ES update too, unless it was estimated around a mean that was itself a
                # jump (keep_step_repeat off): taken jump after jump, such updates can undo every jump
                step = self.cfg.keep_step and (self.cfg.keep_step_repeat or not jumped)
                if self.reverts:
                    self.undo = np.array(strategy.mean, np.float64)  # (n,) mu_{g+1} without the jump
                strategy.set_mean(jump + es_update if step else jump)
                if self.cfg.reset_momentum:
                    strategy.reset_momentum()
                self.jumped = True
            elif won and self.cfg.confirm and not reverted:  # evaluated again, on the next generation's episodes
                held = self.extras[j].copy()
        self.extras, self.pending, self.rivals = None, 0, []
        if judged is not None:  # the strategy is final: the next population may roll out during the clone
            judged(out)
        mean = mu = np.asarray(strategy.mean, np.float64)  # (n,) mu_{g+1}
        theta_star, info, clones = self._clones(generation, mu)
        out.update(info)
        if info:
            d = theta_star - mu  # (n,) the label direction
            check_undo = self.cfg.revert_paired > 0 and self.undo is not None  # the jump's rival: what it replaced
            rows = [mu + s * d for s in self.cfg.scales] + [c for _, c in clones] \
                + ([held] if held is not None else []) + ([self.undo] if check_undo else []) + [mean]
            self.extras, self.pending = np.stack(rows).astype(np.float32), int(held is not None)
            self.undo_row = int(check_undo)
            self.rivals = [v for v, _ in clones]
        return out

    def _check(self, generation: int, j: int, extra_returns: np.ndarray, map_tasks) -> tuple[bool, int]:
        """``check_episodes``: the winner ``j`` and the mean run that many more episodes now (the
        generation's common episode stream past the extra ones) and must pass the paired test again on every
        episode the winner was not picked on (its extra ones and these). Its pick, the best of several
        candidates on the population's E episodes, is biased upward there: with four candidates whose true
        gain is zero, about a third pass the paired test on 2 + 4 episodes and about a tenth pass this
        (a simulation under normal paired differences; the planar drone's candidates won 44 of 230
        judgements and never paid, ``docs/benchmarks/heldout_drone_v16``). Returns (won, env steps run).
        The policies see the observation normalizer as updated by this generation (both alike)."""
        c, n = self.host.cfg, self.cfg.check_episodes
        E = c.rollout.episodes
        done = extra_returns.shape[1]  # E + extra_episodes: the common stream's first indices, used
        seeds = seeding.episode_seeds(c.seed, seeding.TRAIN, generation, np.zeros(2), done + n)[:, done:]  # (2, n)
        policies = np.stack([self.extras[j], self.extras[-1]]).astype(np.float32)  # (2, n_params)
        tasks = population_tasks(c.env, c.env_kwargs, self.host.spec, policies, seeds, 2, generation,
                                 max_steps=c.rollout.max_steps, obs_norm=getattr(self.host, "obs_norm", None))
        res = map_tasks(run_task, tasks)
        ret = np.concatenate([np.asarray(r.returns, np.float64) for r in res])  # (2, n): winner, mean
        steps = int(sum(np.asarray(r.lengths).sum() for r in res))
        cand = np.concatenate([extra_returns[j, E:], ret[0]])  # (x + n,) episodes the pick did not see
        mean = np.concatenate([extra_returns[-1, E:], ret[1]])
        return paired_win(cand, mean, self.cfg.accept_margin), steps

    def _clones(self, generation: int, mu: np.ndarray) -> tuple[np.ndarray, dict, list[tuple[int, np.ndarray]]]:
        """``(theta*, its metrics, [(variant, clone)] of the rivals)``: the mean cloned toward the run's labels
        and toward each rival's that has trained (``guides/rival.py``; none when the run's own clone had no
        data). Each clone's rows are read here, in turn; the clones then run concurrently
        (:func:`~shaped_es.guides.concurrent.concurrently`: their kernels release the GIL; each is the same
        computation as alone)."""
        cfg = self.cfg
        start = mu if not cfg.warm_start or self.learner is None else self.learner
        if not self.host.labels.ready:
            return mu, {}, []
        rows = self.host.dagger_rows(generation)
        jobs = [dict(theta=start, rows=rows)]  # clone_mean's keyword arguments, the run's own first
        if int(rows.lengths().sum()) and cfg.steps:  # else no clone, and no rival's
            for rival in getattr(self.host, "rivals", []):
                if not rival.ready:
                    continue
                v, learner = rival.variant, self.rival_learners.get(rival.variant)
                r = self.host.dagger_rows(generation, rival.labels)
                if rival.idle(r):  # labels another rival's clone already has (no goal held in these rows)
                    continue
                if cap := getattr(rival.labels, "max_rows", 0):  # a label source that costs per row (the
                    rng = np.random.default_rng(seeding.derive_seed(  # shooting labels): a random share of the rows
                        self.host.cfg.seed, seeding.SHAPING, generation, rival_clone_key(v), SUBSAMPLE_KEY))
                    r = r.subsample(cap, rng)
                jobs.append(dict(theta=mu if not cfg.warm_start or learner is None else learner, rows=r,
                                 labels=rival.labels, key=rival_clone_key(v), variant=v))
        done = concurrently([lambda j=j: clone_mean(self.host, generation, j["theta"], cfg, rows=j["rows"],
                                                     labels=j.get("labels"), key=j.get("key", CLONE_KEY))
                              for j in jobs])
        (theta_star, info), clones = done[0], []
        if info and cfg.warm_start:
            self.learner = theta_star.copy()
        for j, (theta, rinfo) in zip(jobs[1:], done[1:]):
            if not rinfo:
                continue
            if cfg.warm_start:
                self.rival_learners[j["variant"]] = theta.copy()
            clones.append((j["variant"], theta))
        return (theta_star, info, clones) if info else (mu, {}, [])

    def sleep(self) -> None:
        self.probe_rows = False
        self.extras, self.pending, self.learner = None, 0, None  # a stale learner would start far from the mean
        self.rivals, self.rival_learners = [], {}
        self.jumped, self.undo, self.undo_row = False, None, 0

    def state_dict(self) -> dict[str, np.ndarray]:
        n = self.host.spec.num_params
        return {"extras": np.zeros((0, n), np.float32) if self.extras is None else self.extras.copy(),
                "pending": np.array(self.pending, np.int64),
                "learner": np.zeros(0) if self.learner is None else self.learner.copy(),
                "jumped": np.array(self.jumped, np.int64),
                # the rows' variants (a checkpoint from before several rivals held a count: 0 or 1)
                "rival_rows": np.array(self.rivals, np.int64),
                "undo": np.zeros(0) if self.undo is None else self.undo.copy(),
                "prev_pop": np.array(self.prev_pop, np.float64),
                "undo_row": np.array(self.undo_row, np.int64),
                **{_learner_key(v): x.copy() for v, x in self.rival_learners.items()}}

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        x = np.asarray(state.get("extras", np.zeros((0, 0))), np.float32)
        pending = int(np.asarray(state.get("pending", 0)))
        if "rival_rows" in state:
            rivals = [int(v) for v in np.asarray(state["rival_rows"], np.int64).reshape(-1)]
        else:  # a checkpoint of a single rival frame: a count
            rivals = [1] * int(np.asarray(state.get("rivals", 0)))
        known = {r.variant for r in getattr(self.host, "rivals", [])}
        if not set(rivals) <= known or len(set(rivals)) != len(rivals):
            raise ValueError(f"the checkpoint holds rival candidates {rivals} but this run has rival label "
                             f"variants {sorted(known)}")
        undo_row = int(np.asarray(state.get("undo_row", 0)))  # a checkpoint from before: no undo row
        k, n = len(self.cfg.scales) + 1 + pending + undo_row + len(rivals), self.host.spec.num_params
        if pending not in (0, 1) or undo_row not in (0, 1) or x.size and (x.shape != (k, n) or not np.isfinite(x).all()):
            raise ValueError(f"candidate extras have shape {x.shape}, expected ({k}, {n}) and finite")
        self.learner = self._vector(state, "learner", n)
        self.rival_learners = {v: x_ for v in known if (x_ := self._vector(state, _learner_key(v), n)) is not None}
        self.jumped = bool(np.asarray(state.get("jumped", 0)))  # a checkpoint from before: no jump pending
        self.undo = self._vector(state, "undo", n)
        pop = np.asarray(state.get("prev_pop", np.zeros(3)), np.float64).reshape(-1)
        if pop.shape != (3,) or not np.isfinite(pop).all() or pop[1] < 0 or pop[2] < 0:
            raise ValueError(f"candidate prev_pop is {pop.tolist()}, expected (mean, variance >= 0, size >= 0)")
        self.prev_pop = (float(pop[0]), float(pop[1]), int(pop[2]))
        self.extras = x if x.size else None
        self.probe_rows = False  # a checkpoint comes after generation 0's judgement
        self.pending = pending if x.size else 0
        self.undo_row = undo_row if x.size else 0
        self.rivals = rivals if x.size else []

    @staticmethod
    def _vector(state: dict[str, np.ndarray], key: str, n: int) -> np.ndarray | None:
        v = np.asarray(state.get(key, np.zeros(0)), np.float64).reshape(-1)
        if v.size and (v.shape != (n,) or not np.isfinite(v).all()):
            raise ValueError(f"candidate {key} has shape {v.shape}, expected ({n},) and finite")
        return v if v.size else None
