"""The generation loop (the paper's Algorithm 1, master side) for every ES method, with exact resume.

One generation::

    X = strategy.ask()                       # (P, n) population
    results = map(rollout, chunks of X)      # returns (P, E) on per-episode seeds from the root seed
    strategy.tell(mean return per member)    # maximize
    guide.after_tell(...)                    # guided / shaped: surrogate subspace for the next ask
    evaluate the tested policy (rollout.test_policy: the mean or the best member); append a metrics row;
    checkpoint atomically

The test episodes of generation g (``eval_overlap``, the default) are submitted as soon as its tested
policy is known and collected after generation g+1's rollouts, so they overlap the update, the shaping
work and the next rollouts (the paper's separate evaluation workers; ``eval_workers`` gives them their
own pool). Rows are still written in generation order and hold exactly what a blocking evaluation
gives; a checkpoint stores the rows still waiting (and their members), and resume submits their test
episodes again.

``clone_overlap`` (the shaped guide's candidate, master placement; the inline and process executors): the
guide calls ``ready(mask)`` from ``after_tell`` once the strategy is final and only its clone of the mean
is left; the trainer then asks for generation g+1 (a strategy whose ``ask`` changes nothing it checkpoints,
``pure_ask``) and submits that population's tasks, which roll out during the clone, the checkpoint and
the start of ``step(g+1)``; ``step(g+1)`` collects them if they are exactly the tasks it would submit
(same members, record mask) and submits the guide's extra members (the clone's candidate) as tasks of
their own. Results, rows and checkpoints are the sequential loop's; a resume simply submits again.

A checkpoint holds the strategy's and the guide's state; ``resume`` reloads the newest one, drops
metrics rows written after it, and continues, giving the rows an uninterrupted run would have given.

``es.obs_norm`` (running observation normalization, ARS V2): every member of generation g sees its
observations through the normalizer of the statistics after generation g-1 (``policies.ObsStats``,
float64), and its test episodes through the same one; after ``tell`` the population's training
observations of generation g (each member's count, sum and sum of squares, merged in member order:
the same numbers whatever the executor or worker count) update the statistics, and the guide's
``after_tell`` gets the normalizer of the updated statistics (``guide.obs_norm``: the shaped guide's clones
are policies of generation g+1, fitted on normalized states). The checkpoint holds
them (``policy/obs_count``, ``policy/obs_mean``, ``policy/obs_m2``: the "mean" policy's normalizer)
and the normalizer the best policy was tested with (``policy/best_obs_mean``, ``policy/best_obs_std``).

Here: :class:`Trainer`'s generation (ask, roll out, tell, guide, the overlapped next population).
``build.py`` the strategy, guide and executor options of a run; ``rows.py`` the metrics rows and their
test episodes; ``state.py`` what a checkpoint holds and how a resume takes it back.
"""

from __future__ import annotations

import time
from concurrent.futures import Future
from dataclasses import dataclass

import numpy as np
from threadpoolctl import threadpool_limits

from shaped_es import seeding
from shaped_es.config import RunConfig, dump_config
from shaped_es.executors import Executor, InlineExecutor, ProcessExecutor, make_executor
from shaped_es.methods import METHODS
from shaped_es.policies import ObsNorm, ObsStats
from shaped_es.rollout import (EnvProbe, mean_returns, policy_spec, population_tasks, probe_env, run_task,
                               run_tasks, warn_if_endless, warn_if_unseeded)
from shaped_es.run_loop import RunLoop
from shaped_es.rundir.store import RunStore
from shaped_es.trainer.build import _executor_options, build_guide, build_strategy, check_obs_norm, startup_notice
from shaped_es.trainer.rows import TIME_COLUMNS, Rows, _Row  # noqa: F401 - TIME_COLUMNS: re-exported
from shaped_es.trainer.state import CheckpointState, DivergedError


def train(cfg: RunConfig, store: RunStore, progress: bool = True, probe: EnvProbe | None = None,
          callback=None) -> list[dict]:
    """Train (or resume) an ES run into ``store``; returns the metrics rows written (``Trainer.run``;
    ``callback``: see :mod:`shaped_es.monitor.callbacks`)."""
    return Trainer(cfg, store, progress=progress, probe=probe, callback=callback).run()


@dataclass
class _Next:
    """The next generation's population rollouts, started while the guide clones (``clone_overlap``)."""

    generation: int
    X: np.ndarray  # (P, n) float32 the population asked for
    record: np.ndarray  # (P,) its record mask
    tasks: list
    futures: list[Future]


class Trainer(CheckpointState, Rows, RunLoop):
    """The ES generation loop (:class:`RunLoop` holds the lock, restores, writes rows and checkpoints;
    :class:`CheckpointState` what a checkpoint holds, :class:`Rows` the metrics rows and test episodes)."""

    def __init__(self, cfg: RunConfig, store: RunStore, executor: Executor | None = None,
                 progress: bool = True, probe: EnvProbe | None = None, callback=None):
        check_obs_norm(cfg)
        super().__init__(cfg, store, cfg.method, progress, callback)
        startup_notice(cfg, progress, self.label)  # before the start-up that compiles the kernels
        self._own_executor = executor is None
        self.executor = executor or make_executor(
            cfg.executor, workers=cfg.workers, **_executor_options(cfg)
        )
        self.eval_executor = self.executor
        try:
            self._start(cfg, store, probe)
        except BaseException:  # a Ctrl-C during the label probe too: the workers it started (some may still be
            self._close_executors()  # starting, and would die on their pool's semaphores with a traceback) end here
            raise

    def _start(self, cfg: RunConfig, store: RunStore, probe: EnvProbe | None) -> None:
        """The rest of the construction, once the executor exists (the label probe uses its workers)."""
        if cfg.eval_workers and cfg.executor == "process" and self._own_executor:
            self.eval_executor = make_executor("process", workers=cfg.eval_workers,  # worker indices
                                               first_index=self.executor.workers,  # after training's
                                               **_executor_options(cfg))
        self._waiting: list[_Row] = []  # rows of finished generations, in order, awaiting test results
        self._next: _Next | None = None  # the next generation's population rollouts, already running
        self.overlapped = 0  # generations whose population rolled out during the previous clone (this process)
        # the env made once before the first rollout (dims; the reset info if the guide reads it)
        probe = probe or probe_env(cfg.env, cfg.env_kwargs, reset=METHODS[cfg.method].probe_reset)
        self.spec = policy_spec(cfg, probe)
        warn_if_endless(cfg.env, probe, cfg.rollout.max_steps)
        warn_if_unseeded(cfg.env, probe)
        x0 = seeding.initial_mean(self.spec, cfg.seed)
        self.strategy = build_strategy(cfg, x0)
        self.guide = build_guide(cfg, self.spec, store, probe, self.executor)
        if hasattr(self.guide, "progress"):
            self.guide.progress = self.progress
        self.best_params = np.asarray(self.strategy.mean, dtype=np.float32).copy()
        # es.obs_norm: the running statistics (None: off) and the normalizer best_params was tested with
        # (a shaped run's start from its label probe's data, so the probe's candidate, judged at generation 0, keeps
        # its inputs at generation 1: guides/clone_probe.probe_stats)
        self.obs_stats = None
        if cfg.es.obs_norm:
            start = getattr(self.guide, "start_obs_stats", None)
            self.obs_stats = start if start is not None else ObsStats.empty(self.spec.obs_dim)
        self.best_norm = self.obs_norm()

    def obs_norm(self) -> ObsNorm | None:
        """The normalizer the next generation's members see (None: es.obs_norm off)."""
        return None if self.obs_stats is None else self.obs_stats.norm()

    def columns(self) -> tuple[str, ...]:
        return super().columns() + tuple(self.guide.metric_keys())

    # -- checkpointing -----------------------------------------------------------------------------
    def checkpoint(self) -> None:
        super().checkpoint()
        after = getattr(self.guide, "after_checkpoint", None)
        if after is not None:  # the checkpoint is durable: what only older ones needed may go
            after(self.c.generation)

    # -- one generation ----------------------------------------------------------------------------
    def _tasks(self, params: np.ndarray, seeds: np.ndarray, g: int, record, obs_stats: bool = False):
        """Training rollout tasks of ``params`` ``(m, n)`` (``obs_stats``: their observations' sums too)."""
        return population_tasks(self.cfg.env, self.cfg.env_kwargs, self.spec, params, seeds,
                                self.executor.workers, g, record, self.cfg.rollout.max_steps,
                                expert=self.guide.expert, obs_norm=self.obs_norm(),
                                obs_stats=obs_stats and self.obs_stats is not None,
                                position_period=self.guide.position_period)

    def step(self, g: int) -> list[dict]:
        """Run generation ``g``; returns the metrics rows completed meanwhile (in order; with
        ``eval_overlap`` the row of ``g`` itself usually arrives with the next generation's)."""
        t0, cpu0 = time.perf_counter(), time.process_time()
        X = np.asarray(self.strategy.ask(), dtype=np.float32)  # (P, n)
        self.guide.begin_generation(g)
        extra = self.guide.extra_members(g)  # (k, n) evaluated beside the population, or None
        X_all = X if extra is None else np.concatenate([X, np.asarray(extra, np.float32)])  # (P + k, n)
        P = X.shape[0]
        results, rollout_time = self._roll_out(X_all, g, P)
        done = self._drain()  # the previous generation's test episodes ran alongside these rollouts
        fitness = mean_returns(results)  # (P + k,) each member's mean return
        item = self._start_row(g, X_all, fitness, P)  # the best member's test episodes start now
        old_mean = np.array(self.strategy.mean, copy=True)
        self.strategy.tell(fitness[:P])  # maximize
        self._update_obs_stats(results)  # generation g+1's members see the observations of 0..g
        self.guide.obs_norm = self.obs_norm()  # what the policies the guide makes now will see
        ready = (lambda mask: self._start_next(g + 1, mask)) if self._overlaps(g) else None
        extra = self.guide.after_tell(g, X, results, old_mean, self.strategy, self.executor.map, ready=ready)
        if not np.isfinite(self.strategy.mean).all():  # nothing of generation g is written
            raise DivergedError(self._diverged(g, "the search mean"))
        return done + self._end_row(g, item, results, old_mean, extra, rollout_time, t0, cpu0)

    def _overlaps(self, g: int) -> bool:
        """Whether generation ``g+1``'s population may start rolling out during ``g``'s ``after_tell``
        (``clone_overlap``): not after the last generation; only on the inline and process executors, and
        with a strategy whose ``ask`` leaves its checkpointed state alone (``pure_ask``: the checkpoint
        after ``g``, written while those rollouts run, is the one the sequential loop writes)."""
        return (self.cfg.clone_overlap and g + 1 < self.cfg.generations
                and isinstance(self.executor, (InlineExecutor, ProcessExecutor))  # ray / mpi: sequential
                and bool(getattr(self.strategy, "pure_ask", False)))

    def _start_next(self, g: int, record: np.ndarray) -> None:
        """Submit generation ``g``'s population rollout tasks now (the guide's ``ready``: the strategy is
        final, the guide's clone follows); ``record`` ``(P,)``: their record mask. ``step(g)`` uses them if
        they are the tasks it would submit itself (the same members, mask and normalizer), else runs its own."""
        if self._next is not None or not np.isfinite(self.strategy.mean).all():
            return
        X = np.asarray(self.strategy.ask(), dtype=np.float32)  # (P, n) what step(g) asks again
        cfg, P = self.cfg, X.shape[0]
        seeds = seeding.episode_seeds(cfg.seed, seeding.TRAIN, g, np.arange(P), cfg.rollout.episodes,
                                      cfg.rollout.common_seeds)  # (P, E)
        record = np.asarray(record, dtype=bool).reshape(-1)
        tasks = self._tasks(X, seeds, g, record, obs_stats=True)
        self._next = _Next(g, X, record, tasks, [self.executor.submit(run_task, t) for t in tasks])

    def _update_obs_stats(self, results: list) -> None:
        """Merge the population's observation sums (its members' ``RolloutResult.obs_stats``, in member
        order) into the running statistics (es.obs_norm)."""
        if self.obs_stats is None:
            return
        parts = [r.obs_stats for r in results if r.obs_stats is not None]  # the population's tasks, in order
        count, total, squares = (np.concatenate([p[k] for p in parts]) for k in range(3))  # (P,), (P, d), (P, d)
        batch = ObsStats.from_sums(float(count.sum()), total.sum(axis=0), squares.sum(axis=0))
        self.obs_stats = self.obs_stats.merge(batch)

    def _roll_out(self, X: np.ndarray, g: int, P: int) -> tuple[list, float]:
        """Every member of ``X`` ``(P + k, n)`` (the population, then the guide's extra members) on
        generation ``g``'s training episode seeds; the results in member order (returns ``(m, E)``; the
        extras ``(m, E + x)`` with ``x`` = the guide's ``extra_episodes``: their first E episodes are the
        population's, with common seeds) and the time the rollouts took."""
        cfg = self.cfg
        E, k = cfg.rollout.episodes, X.shape[0] - P
        seeds = seeding.episode_seeds(cfg.seed, seeding.TRAIN, g, np.arange(P), E, cfg.rollout.common_seeds)  # (P, E)
        fn = self.guide.rollout_fn()
        t_roll = time.perf_counter()
        record = self.guide.record_mask(P, k)  # (P + k,)
        pre, self._next = self._next, None
        if not (pre is not None and pre.generation == g and fn is None and np.array_equal(pre.X, X[:P])
                and np.array_equal(pre.record, record[:P])):
            pre = None  # not started during the last clone (or not these tasks: run as usual)
        tasks = pre.tasks if pre is not None else self._tasks(X[:P], seeds, g, record[:P], obs_stats=True)
        extra = []
        if k:  # the extras, with their extra episodes, in tasks of their own
            x = self.guide.extra_episodes()
            b = min(self.guide.unjudged_extras(), k) if x else 0  # the last b: never judged, E episodes
            xs = seeding.episode_seeds(cfg.seed, seeding.TRAIN, g, np.arange(P, P + k), E + x,
                                       cfg.rollout.common_seeds)  # (k, E + x)
            extra = self._tasks(X[P : P + k - b], xs[: k - b], g, record[P : P + k - b]) if k > b else []
            for t in extra:
                t.members = t.members + P  # population indices P .. P + k - b - 1
            if b:  # the unjudged (babblers): the first E of their seeds, the population's common episodes
                data_only = self._tasks(X[P + k - b :], xs[k - b :, :E], g, record[P + k - b :])
                for t in data_only:
                    t.members = t.members + P + k - b
                extra += data_only
        if pre is not None:
            self.overlapped += 1
            # the population has been rolling out since the guide's clone began; the extras (the clone's
            # candidate, the babblers) could not start before it: their chunks as tasks of their own, one
            # a worker, queued behind the population's (in one call on one worker they were a serial tail:
            # UR5Reach-v0 idle, 2.53x a vanilla generation against 2.18x without the overlap)
            done = self.executor.map(run_task, extra) if extra else []
            results = self.executor.collect(run_task, tasks, pre.futures) + done
        elif fn is None and extra:
            # population chunk i with extras tasks i, i + c, ... in one call, one lock-step loop
            # (rollout.run_tasks: the same results as apart), not a second wave of small tasks on the workers
            c = len(tasks)
            bundles = [[a] + extra[i::c] for i, a in enumerate(tasks)]
            done = self.executor.map(run_tasks, bundles)
            ex = [None] * len(extra)  # the extras back in member order
            for i, d in enumerate(done):
                ex[i::c] = d[1:]
            results = [d[0] for d in done] + ex  # population, then extras
        else:
            results = self.executor.map(fn or run_task, tasks + extra)
        return results, time.perf_counter() - t_roll

    def finish(self) -> list[dict]:
        return self._drain()

    def run(self) -> list[dict]:
        """Run (or continue) to ``cfg.generations``; returns the rows written by this call."""
        # The master's linear algebra is small (QR of (n, k), M_phi minibatches): one thread avoids
        # oversubscribing the cores the workers use (multi-threaded BLAS was 100x slower here).
        with threadpool_limits(limits=1):
            _limit_torch_threads()
            return super().run()

    def close(self) -> None:
        super().close()
        self.guide.close()
        self._close_executors()

    def _close_executors(self) -> None:
        if self._own_executor:
            if self.eval_executor is not self.executor:
                self.eval_executor.shutdown()
            self.executor.shutdown()


def _limit_torch_threads() -> None:
    import sys

    if "torch" in sys.modules:  # only the shaped method and TensorBoard load torch in the master
        sys.modules["torch"].set_num_threads(1)


__all__ = ["Trainer", "dump_config"]
