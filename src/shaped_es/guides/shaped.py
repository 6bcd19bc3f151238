"""The shaped method (``--method shaped``) as a guide of the generation loop: its data, ``M_phi`` and
labels; *how* the labels become search is its mechanism (``shaping.mechanism``, ``guides/mechanisms/``:
the paper's subspace, the mean's clone as a candidate, or as a pair).

Per generation ``g`` (timeline; ``||`` = concurrently)::

    begin_generation(g):  M_phi.add(recorded steps of g-1)  ->  train M_phi in a thread  ||  workers roll
                          out Theta_g and the mechanism's extra members (recording the mechanism's mask)
    strategy.tell(R_g)    -> mu_{g+1}
    after_tell(g):        join M_phi; mechanism.after_tell: e.g. (paper) label every member's D_i and
                          clone theta_i -> theta*_i; Delta = (Theta* - mu_{g+1}) / eta; strategy.guide(Delta)
                          -> the next ask samples from Sigma = alpha/n I + (1 - alpha)/k U U^T (scaled by n)

The candidate mechanism with the trainer's ``clone_overlap`` (opt-in; master placement, inline/process
executors)::

    after_tell(g):        join M_phi; judge c_g (accept: mu_{g+1} := c_g) and the label budget's verdict
                          -> ready(mask): the trainer asks Theta_{g+1} and submits its rollouts  ||  the
                          master clones mu_{g+1} -> theta*_{g+1} (Numba, GIL released) -> c_{g+1}
    checkpoint(g)         ||  Theta_{g+1} still rolling out (ask is pure: the checkpoint is the sequential one)
    begin_generation(g+1) -> the candidate's and babblers' chunks go now, as one worker call behind the
                          population's tasks (rollout.run_tasks);
                          M_phi trains on g's steps (after the clone: its labels are the ones cloned toward)

The same tasks, seeds and results as the sequential loop (tested): only when they start differs.
CarNav-v0, 2 process workers on the shared 2-core machine: see ``docs/shaped-results.md``, "What shaping
costs".

Labels come from ``shaping.labels`` (``shaping/labels.py``): M_phi's (the paper; M_phi is trained only
then), a reference run's policy, or the env's scripted controller (oracles). M_phi lags one generation
behind the rollouts (it trains on g-1 while g runs), as the paper overlaps its training with the
workers. Labels are taken only after the training thread has joined, so results do not depend on timing.

Where the shaping work runs (``shaping.placement``; both give the same numbers, tested):

- ``master``: the rollouts send their transitions back with the returns (~2 MB a generation for
  CarNav-v0); the master keeps the last ``history`` generations in memory, labels the rows the cloning
  draws in one batch, straight into shared memory, runs the gradient steps in chunks on the (then idle)
  process workers, which read those rows from there (or itself, inline), and writes one trajectory shard
  per generation in a background thread (joined before each checkpoint: the durable copy is what resume
  reads). Shards and M_phi's data parts are pruned once the
  next checkpoint is on disk.
- ``workers``: the paper's cluster picture. Each worker writes its chunk's shard to the trajectory
  store (any pyarrow URI) and, for cloning, reads its members' ``D_i`` from its own in-memory cache or
  the store; only returns and ``theta*`` travel.
- ``auto`` (default): ``master`` on one machine (``inline`` / ``process`` executors) while the
  population's parameters ``P x n`` stay below ``MASTER_MAX_PARAMS`` (the batched cloning then fits in a
  few hundred MB), ``workers`` on ``ray`` / ``mpi`` or beyond that size.

This file holds the guide's state (its constructor) and its generation hooks ``begin_generation`` and
``after_tell``; the rest of the guide lives in its base classes, one file each. The rollout hooks (which
members run beyond the population and whose steps are recorded: ``extra_members``, ``record_mask``, ...) in
``guides/shaped_rollouts.py`` (``RolloutHooks``); the generations' recorded steps as the guide reads them (in
memory, or from the store) and the rows the cloning draws from them in ``guides/shaped_data.py``
(``GenerationData``); the shaping thread's work, the writer thread's writes and their pruning after a
checkpoint in ``guides/shaped_background.py`` (``BackgroundWork``); the mechanism's judgement and clone (the
shaped part of ``after_tell``), the label budget's verdicts and the back-off note in
``guides/shaped_verdicts.py`` (``LabelVerdicts``); the checkpoint's ``state_dict`` / ``load_state_dict`` in
``guides/shaped_checkpoint.py`` (``GuideCheckpoint``).
"""

from __future__ import annotations

import dataclasses
import sys
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import numpy as np

from shaped_es.config import RunConfig
from shaped_es.data import PackedTransitions, join_packed
from shaped_es.guides import NoGuide
from shaped_es.methods import MECHANISMS, resolve
from shaped_es.policies import MLPSpec
from shaped_es.rollout import EnvProbe
from shaped_es.shaping import kernels
from shaped_es.shaping.cloning import CloningConfig, warm_up_cloning
from shaped_es.shaping.shared_rows import SharedRows
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.settings import MeanCloneConfig
from shaped_es.shaping.trajectories import delete_generations, run_root, write_shard
from shaped_es.guides.label_budget import LabelBudget
from shaped_es.guides.label_check import probe_line, source_line
from shaped_es.guides.probe_file import FILE as PROBE_FILE, load_or_probe, start_stats
from shaped_es.guides.mphi_track import MphiTrack
from shaped_es.guides.mechanisms.mean_clone import noise_scale
from shaped_es.guides.mechanisms.paper import REFERENCE_METRICS
from shaped_es.guides.reference import reference_actions
from shaped_es.guides.rival import names as rival_names, owned, probe_shooting, rivals
from shaped_es.guides.shaped_background import FIT_TEST_ROWS, BackgroundWork  # noqa: F401 (FIT_TEST_ROWS)
from shaped_es.guides.shaped_checkpoint import GuideCheckpoint
from shaped_es.guides.shaped_rollouts import RolloutHooks
from shaped_es.guides.shaped_verdicts import LabelVerdicts
from shaped_es.guides.shaped_data import GenerationData, _Block
from shaped_es.guides.shaped_setup import (check_obs_norm, from_section, label_source, mphi_config, placement,
                                          waypoint_dim, wrap_line, write_wrap_file)

MPHI_KEYS = ("mphi_train_loss", "mphi_fit_test_loss", "mphi_iterations", "mphi_dataset_size",
             "mphi_kept_fraction", "time_mphi_s", "time_mphi_wait_s")
COMMON_KEYS = ("time_cloning_s", "clone_cpu_time_s", "time_store_write_s", "shaping_active", "shaping_awake")
DIAGNOSE_KEYS = ("clone_return_gain", "clone_improved_fraction")  # only with shaping.diagnose_returns


# NoGuide last: the parts' hooks (record_mask, state_dict, ...) override its defaults
class ShapedGuide(RolloutHooks, GenerationData, BackgroundWork, LabelVerdicts, GuideCheckpoint, NoGuide):
    record = True

    def __init__(self, cfg: RunConfig, spec: MLPSpec, store, probe: EnvProbe | None = None, executor=None):
        check_obs_norm(cfg)  # es.obs_norm: mechanism candidate only (preflight says so first)
        self.cfg, self.spec, self.sh = cfg, spec, cfg.shaping
        self.traj_root = run_root(self.sh.trajectory_root, str(store.trajectories_dir), store.run_id())
        self.run_name = Path(store.root).name  # the run's lines name it (a benchmark's --quiet runs print in turn)
        self.progress = True  # False (the trainer's --quiet): informational lines the same in every run not said
        self.placement = placement(cfg, spec)
        mp = self.sh.inverse_dynamics
        pos_dim = waypoint_dim(cfg, probe)
        self.mphi_cfg = mphi_config(cfg, pos_dim)
        wraps, self._wrap_declared, period = wrap_line(cfg, pos_dim)  # declared: position_period (_check_wrap)
        self._wrap_warned = False  # rows that still jump by a turn: one line (_check_wrap)
        self.store_root, self.position_period = store.root, None  # (d,): a wrap the start missed (_check_wrap)
        if wraps and not Path(store.metrics_path).exists():  # a new run: before the probe
            print(f"shaped-es: {self.run_name}: {wraps}", file=sys.stderr)
            write_wrap_file(store.root, period, self._wrap_declared)
        self.query_clip = mp.query_clip  # times the mean training step (None: the query as asked)
        self.startup = (0, 0.0)  # env steps and seconds spent before generation 0 (the label probe)
        # the compiled shaping kernels: loaded from Numba's cache (~0.1 s), or compiled once per install
        # (~10-30 s), not on the clock: before the label probe, which uses them and whose seconds count
        self.kernels_load_s = kernels.warm_up() if kernels.ENABLED else 0.0
        probe_res = None  # a fresh probe's result, printed once the rivals are known
        shooting = {}  # the shooting rivals the probe gives (rival.probe_shooting; none: not probed, the config's)
        self.has_controller = bool(probe is not None and probe.controller)  # the back-off note's hint
        self._metrics_path = Path(store.metrics_path)  # the back-off note reads its test rewards (_past_threshold)
        self._probe_res = None  # the label probe's result (None: no probe): its candidate, generation 0's line
        # the line at the first clone fitted under parameter noise (mean_clone.noise_from); None: resumed, not known
        self._noise_said: bool | None = False
        # the strategy's search_scale() after its tell, the unit of the clone's noise (es.sigma for Vanilla-ES and
        # Guided ES; CMA-ES's adapted step), set in after_tell before the mechanism clones
        self.search_sigma = float(cfg.es.sigma)
        if mp.frame == "auto" and self.sh.labels == "mphi":  # guides/label_probe.py (a line: world frame only)
            res, fresh = load_or_probe(Path(store.root) / PROBE_FILE, cfg, spec, pos_dim, self.mphi_cfg, executor,
                                       lambda line: print(f"shaped-es: {self.run_name}: {line}", file=sys.stderr,
                                                          flush=True))
            self.mphi_cfg = dataclasses.replace(self.mphi_cfg, frame=res.frame, step_change=bool(res.step_change), **(
                {} if res.chunk is None else {"targets": "chunk", "horizon": res.chunk}))  # the probe's M_phi
            self.query_clip = res.query_clip
            # counted in generation 0's row, also by a run that restarts it with the probe on file
            self.startup = (res.env_steps, res.seconds)
            probe_res = res if fresh else None
            shooting = probe_shooting(res, mp)
            self._probe_res = res
        self.clone_cfg = from_section(CloningConfig, self.sh.cloning)
        self.mean_clone_cfg = from_section(MeanCloneConfig, self.sh.mean_clone)
        # M_phi exists (and trains) only when it is the label source
        self.mphi = (InverseDynamics(spec.obs_dim, pos_dim, spec.act_dim, self.mphi_cfg)
                     if self.sh.labels == "mphi" else None)
        self.reference = reference_actions(self.sh.reference_run, spec) if self.sh.reference_run else None
        self.labels = label_source(cfg, spec, self.mphi, self.mphi_cfg, self.reference, probe)
        # rival label variants whose labels make more candidates (guides/rival.py): another frame, servo, shooting
        self.rivals = [] if self.mphi is None else rivals(cfg, self.mphi_cfg.frame, spec.obs_dim, pos_dim,
                                                          spec.act_dim, self.mphi_cfg, Path(store.root), **shooting)
        if probe_res is not None:  # the probe's choice, and the rivals beside it
            judged = self.sh.mean_clone.probe_candidate and self.sh.mechanism == "candidate"  # at generation 0
            print(f"shaped-es: {self.run_name}: " + probe_line(probe_res, cfg.env, rival_names(self.rivals), judged),
                  file=sys.stderr)
        elif self.sh.labels != "mphi" and not Path(store.metrics_path).exists():  # a new run: say where labels
            # come from (a new user's controller-label runs printed nothing about their labels)
            print(f"shaped-es: {self.run_name}: {source_line(self.sh.labels)}", file=sys.stderr)
        self.mechanism = resolve(MECHANISMS[self.sh.mechanism])(self)
        self.step_norm = np.zeros(2)  # (count, mean) of training displacement norms (kept rows), for query_clip
        self._thread: threading.Thread | None = None
        self._thread_error: BaseException | None = None
        self._pending: dict = {}
        self._last_generation = -1  # the newest generation whose after_tell ran
        self._cache: dict[int, _Block] = {}  # master placement: generation -> its block in memory
        self._writer = ThreadPoolExecutor(1, thread_name_prefix="shaping-writer")
        self._writes: list[Future] = []
        self._write_time = 0.0  # background write time not yet reported
        # M_phi's data set is saved once, as the rows each generation added (RUN/mphi_data, mphi_parts.py),
        # not in every checkpoint; a checkpoint names the parts that rebuild it (the rival's: its own)
        self.track = None if self.mphi is None else MphiTrack(self.mphi, self.labels, Path(store.root) / "mphi_data")
        self._tracks = [t for t in (self.track, *(r.track for r in owned(self.rivals))) if t is not None]
        # generations of slack for the older checkpoints kept on disk (a fallback if the newest is lost)
        self._ckpt_margin = (cfg.keep_checkpoints - 1) * cfg.checkpoint_every
        # (generation, the oldest data part of each of _tracks) of the last state_dict
        self._saved: tuple[int, list[int]] | None = None
        # master placement on local processes: labels here, the gradient steps in the idle workers
        self.fit_on_workers = self.placement == "master" and cfg.executor == "process"
        self.shared_rows = SharedRows() if self.fit_on_workers else None  # the rows the workers' fits read
        self.population = 2 * cfg.es.pairs
        self._warned = False
        self._babblers = 0  # babbling policies among this generation's extra members (the last rows)
        # labels that keep losing put the shaping work to sleep (guides/label_budget.py)
        self.budget = LabelBudget(self.sh.backoff_after, self.sh.backoff_max,
                                  judge_jumps=self.sh.backoff_judges_jumps, keep_rate=self.sh.backoff_keep_rate,
                                  heavy=self.sh.backoff_heavy)
        self.awake = True  # this generation is shaped (False: asleep, a Vanilla-ES generation)
        self._silent: set[int] = set()  # recent generations slept through: no steps were recorded
        if self.placement == "master" and self.clone_cfg.batch_size <= 0:  # full-data cloning runs in torch
            warm_up_cloning()  # torch's first optimizer imports torch._dynamo (~1-7 s): not on the clock

    def metric_keys(self) -> tuple[str, ...]:
        """The metrics columns this run's guide fills (M_phi's only with M_phi labels; the reference
        label metrics only with ``shaping.reference_run``)."""
        keys = (MPHI_KEYS if self.mphi is not None else ()) + COMMON_KEYS + self.mechanism.metric_keys
        if self.reference is not None:
            keys += REFERENCE_METRICS
        if not self.sh.diagnose_returns:
            keys = tuple(k for k in keys if k not in DIAGNOSE_KEYS)
        return tuple(dict.fromkeys(keys))

    @property
    def probe_candidate(self) -> np.ndarray | None:
        """The label probe's best simulated candidate ``(n,)``, judged beside generation 0 (None: none kept)."""
        return None if self._probe_res is None else self._probe_res.candidate_params

    @property
    def start_obs_stats(self):
        """es.obs_norm: the observation statistics the run starts from, the label probe's data's
        (``probe_file.start_stats``; None: no probe, or off)."""
        return None if self._probe_res is None else start_stats(self._probe_res, self.spec.obs_dim)

    def _write(self, packed: PackedTransitions) -> float:
        """The writer thread's job for one generation's block (master placement): its shard."""
        t0 = time.perf_counter()
        write_shard(self.traj_root, packed)
        return time.perf_counter() - t0

    # -- M_phi, concurrently with the rollouts -----------------------------------------------------
    def begin_generation(self, generation: int) -> None:
        self._pending = dict.fromkeys(self.metric_keys())
        self._join_writes()
        self._after_checkpoint()  # the previous generation's checkpoint is durable by now
        # shards a killed run left for this generation (maybe laid out by another placement) go first
        delete_generations(self.traj_root, [generation])
        self.awake = self.budget.begin()
        if not self.awake:  # a Vanilla-ES generation: no data, no M_phi, no mechanism work
            self._silent.add(generation)
            return
        self._silent.discard(generation)
        if self.mphi is not None:
            self._pending.update(time_mphi_s=0.0, mphi_iterations=self.mphi.iterations,
                                 mphi_dataset_size=self.mphi.dataset_size)
        train = self.mphi is not None and generation > 0 and not (self.sh.early_mphi and generation == 1)
        # g-1's steps read here (a lost shard: a loud error on this thread), trained on beside the rollouts
        data = [t for t in self._generation(generation - 1) if len(t)] if train else []
        # the mechanism's work that may overlap the rollouts (after M_phi's training, in the same thread)
        job = self.mechanism.background_job(generation)
        if train or job is not None:
            self._thread = threading.Thread(target=self._background, args=(generation, data, train, job),
                                            name="shaping", daemon=True)
            self._thread.start()

    # -- the labels' use: the mechanism (guides/mechanisms/; its judgement and clone: shaped_verdicts.py) --
    def after_tell(self, generation, params, results, old_mean, strategy, map_tasks, ready=None) -> dict:
        """``ready(mask)`` (the trainer's ``clone_overlap``; None: off): called once the mechanism's
        judgement is made and the strategy final, before its clone, with the next generation's population
        record mask ``(P,)``; the trainer then starts that population's rollouts (master placement only: the
        workers placement's tasks write shards that the next ``begin_generation`` first clears)."""
        self._write_time += float(sum(getattr(r, "store_time_s", 0.0) for r in results))  # on the workers
        if self.placement == "master":  # keep the generation in memory
            blocks = [r.packed for r in results if r.packed is not None]  # one per task that recorded
            for r in results:
                r.packed = None
            self._remember(generation, join_packed(blocks) if blocks else None)
            blk = self._cache[generation]
            self._check_wrap(generation, blk.big)
            if blk.packed is not None:
                self._writes.append(self._writer.submit(self._write, blk.packed))
        t_wait = time.perf_counter()
        self._join_thread()
        self._early_mphi(generation)  # shaping.early_mphi: generation 1's M_phi work, before generation 0's clone
        out = dict(self._pending, time_cloning_s=0.0, clone_cpu_time_s=0.0, shaping_active=0,
                   time_store_write_s=self._write_time)  # this generation's shards (+ M_phi data parts)
        if self.mphi is not None:
            out["time_mphi_wait_s"] = time.perf_counter() - t_wait
        self._write_time = 0.0
        if self._noise_said is None:  # resumed: the run said it before if its generations had reached the noise
            self._noise_said = noise_scale(self.mean_clone_cfg, generation - 1) > 0
        self._last_generation = generation
        out["shaping_awake"] = int(self.awake)
        if not self.awake:
            self._remember(generation, [])
            self._trim_cache(generation)
            return out
        if not self.labels.ready and not self.mechanism.probe_rows:  # M_phi has no data kept
            # yet and no probe candidate to judge (generation 0): this generation stays Vanilla-ES
            self._warn_untrained(generation)
            self._trim_cache(generation)
            return out
        out["shaping_active"] = 1
        self._judge_and_clone(out, generation, params, results, old_mean, strategy, map_tasks, ready)
        self._trim_cache(generation)
        return out

    def close(self) -> None:
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        try:
            self._join_writes()
        finally:
            self._writer.shutdown(wait=True)
            if self.shared_rows is not None:
                self.shared_rows.close()
