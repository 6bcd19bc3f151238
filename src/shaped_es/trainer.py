"""The generation loop (the paper's Algorithm 1, master side) for every ES method, with exact resume.

One generation::

    X = strategy.ask()                       # (P, n) population
    results = map(rollout, chunks of X)      # returns (P, E) on per-episode seeds from the root seed
    strategy.tell(mean return per member)    # maximize
    guide.after_tell(...)                    # guided / shaped: surrogate subspace for the next ask
    evaluate the best member on test episodes; append a metrics row; checkpoint atomically

The test episodes of generation g (``eval_overlap``, the default) are submitted as soon as its best
member is known and collected after generation g+1's rollouts, so they overlap the update, the shaping
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
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Future
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from shaped_es import seeding
from shaped_es.config import ConfigError, RunConfig, dump_config
from shaped_es.executors import Executor, InlineExecutor, ProcessExecutor, make_executor
from shaped_es.methods import METHODS, resolve
from shaped_es.policies import MLPSpec, ObsNorm, ObsStats
from shaped_es.rollout import (EnvProbe, mean_returns, policy_episode_tasks, policy_spec, population_tasks,
                               probe_env, run_task, run_tasks, warn_if_endless)
from shaped_es.run_loop import RunLoop
from shaped_es.shaping.kernel_notice import say_if_compiling
from shaped_es.rundir.store import RunStore
from shaped_es.strategies import Strategy

class DivergedError(RuntimeError):
    """The search went non-finite (inf/NaN mean or state); the run stops, its last good checkpoint kept."""


TIME_COLUMNS = ("wall_time_s", "cpu_time_s", "gen_time_s", "rollout_time_s", "clone_cpu_time_s")


def build_strategy(cfg: RunConfig, x0: np.ndarray) -> Strategy:
    """The strategy of ``cfg.method`` (its entry in :data:`methods.METHODS`) at ``x0`` ``(n,)``."""
    method = METHODS[cfg.method]
    if method.strategy is None:
        raise ValueError(f"method {cfg.method!r} is not an ES method (it has its own run loop)")
    seed = seeding.derive_seed(cfg.seed, seeding.STRATEGY)
    return resolve(method.strategy)(x0, **method.strategy_args(cfg, seed))


def check_obs_norm(cfg: RunConfig) -> None:
    """``ConfigError`` (one line) if ``es.obs_norm`` is set for a method that cannot use it yet
    (``methods.Method.no_obs_norm``)."""
    why = METHODS[cfg.method].no_obs_norm
    if cfg.es.obs_norm and why:
        raise ConfigError(f"es.obs_norm is not supported with --method {cfg.method} yet: {why}; "
                          f"set es.obs_norm=false")


def build_guide(cfg: RunConfig, spec: MLPSpec, store: RunStore, probe: EnvProbe | None = None):
    """The guide of ``cfg.method`` (its entry in :data:`methods.METHODS`); ``probe``: the run's env probe."""
    method = METHODS[cfg.method]
    return resolve(method.guide)(**method.guide_args(cfg, spec, store, probe))


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


@dataclass
class _Row:
    """A metrics row waiting for its generation's test episodes (``futures`` empty: none due)."""

    row: dict
    theta: np.ndarray | None = None
    obs_norm: ObsNorm | None = None  # the normalizer theta's test episodes run with (es.obs_norm)
    tasks: list = field(default_factory=list)
    futures: list[Future] = field(default_factory=list)


def startup_notice(cfg: RunConfig, progress: bool, label: str) -> bool:
    """The line before a cold cache's kernel compile (``shaping/kernel_notice.py``), for the methods that
    use the kernels and not with ``--quiet``; returns whether it printed."""
    return bool(progress and METHODS[cfg.method].kernels and say_if_compiling(label))


class Trainer(RunLoop):
    """The ES generation loop (:class:`RunLoop` holds the lock, restores, writes rows and checkpoints)."""

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
        x0 = self.spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
        self.strategy = build_strategy(cfg, x0)
        self.guide = build_guide(cfg, self.spec, store, probe)
        self.best_params = np.asarray(self.strategy.mean, dtype=np.float32).copy()
        # es.obs_norm: the running statistics (None: off) and the normalizer best_params was tested with
        self.obs_stats = ObsStats.empty(self.spec.obs_dim) if cfg.es.obs_norm else None
        self.best_norm = self.obs_norm()

    def obs_norm(self) -> ObsNorm | None:
        """The normalizer the next generation's members see (None: es.obs_norm off)."""
        return None if self.obs_stats is None else self.obs_stats.norm()

    def columns(self) -> tuple[str, ...]:
        return super().columns() + tuple(self.guide.metric_keys())

    # -- checkpointing -----------------------------------------------------------------------------
    def checkpoint_state(self) -> tuple[dict, dict]:
        arrays = {f"strategy/{k}": v for k, v in self.strategy.state_dict().items()}
        arrays |= {f"guide/{k}": v for k, v in self.guide.state_dict().items()}
        arrays["policy/best"] = self.best_params
        arrays["policy/mean"] = np.asarray(self.strategy.mean, dtype=np.float32)
        if self.obs_stats is not None:  # float64: a resume continues with exactly these statistics
            arrays["policy/obs_count"] = np.array(self.obs_stats.count, dtype=np.float64)
            arrays["policy/obs_mean"], arrays["policy/obs_m2"] = self.obs_stats.mean, self.obs_stats.m2
            arrays["policy/best_obs_mean"], arrays["policy/best_obs_std"] = self.best_norm.mean, self.best_norm.std
        meta = {"policy": {"obs_dim": self.spec.obs_dim, "act_dim": self.spec.act_dim,
                           "hidden": list(self.spec.hidden)}}
        # Rows whose test episodes are still running: resume submits them again (same seeds).
        meta["waiting_rows"] = [_jsonable(item.row) for item in self._waiting]
        for i, item in enumerate(self._waiting):
            if item.theta is not None:
                arrays[f"waiting/{i}"] = item.theta
            if item.obs_norm is not None:
                arrays[f"waiting/{i}/obs_mean"], arrays[f"waiting/{i}/obs_std"] = item.obs_norm.mean, item.obs_norm.std
        bad = _non_finite(arrays)
        if bad:  # never save a state a resume could not continue from; the previous one stays
            raise DivergedError(self._diverged(self.c.generation - 1, f"the state to checkpoint ({bad[0]})"))
        return arrays, meta

    def checkpoint(self) -> None:
        super().checkpoint()
        after = getattr(self.guide, "after_checkpoint", None)
        if after is not None:  # the checkpoint is durable: what only older ones needed may go
            after(self.c.generation)

    def _diverged(self, g: int, what: str) -> str:
        gens = self.store.checkpoints()
        kept = f"generation {gens[-1]}" if gens else "none yet"
        knobs = " / ".join(METHODS[self.cfg.method].knobs)
        return (f"generation {g}: {what} became non-finite (inf/NaN); the run stopped, its last good "
                f"checkpoint ({kept}) is kept; lower {knobs}")

    def load_state(self, arrays: dict, meta: dict) -> None:
        bad = _non_finite(arrays)
        if bad:  # what checkpoint_state never saves: the run would blame its env for the NaN actions
            raise ValueError(f"{bad[0]} holds non-finite values (inf/NaN)")
        waiting = meta.get("waiting_rows", [])
        if not isinstance(waiting, list) or not all(
                isinstance(r, dict) and type(r.get("generation")) is int for r in waiting):
            raise ValueError("malformed waiting_rows")
        self.strategy.load_state_dict(_sub(arrays, "strategy/"))
        self.guide.load_state_dict(_sub(arrays, "guide/"))
        self.best_params = arrays["policy/best"]
        if np.shape(self.best_params) != (self.spec.num_params,):
            raise ValueError(f"policy/best has shape {np.shape(self.best_params)}")
        if self.obs_stats is not None:
            d = self.spec.obs_dim
            self.obs_stats = ObsStats(float(_shaped(arrays, "policy/obs_count", ())),
                                      _shaped(arrays, "policy/obs_mean", (d,)).astype(np.float64),
                                      _shaped(arrays, "policy/obs_m2", (d,)).astype(np.float64))
            self.best_norm = ObsNorm(_shaped(arrays, "policy/best_obs_mean", (d,)).astype(np.float32),
                                     _shaped(arrays, "policy/best_obs_std", (d,)).astype(np.float32))

    def resumed(self, arrays: dict, meta: dict) -> None:
        """Submit the test episodes of the rows still waiting at the checkpoint again (``recover`` kept
        the metrics rows before the first of them)."""
        self._waiting = []
        for i, row in enumerate(meta.get("waiting_rows", [])):
            item = _Row(dict(row))
            if f"waiting/{i}" in arrays:
                norm = None
                if f"waiting/{i}/obs_mean" in arrays:
                    norm = ObsNorm(np.asarray(arrays[f"waiting/{i}/obs_mean"], np.float32),
                                   np.asarray(arrays[f"waiting/{i}/obs_std"], np.float32))
                self._submit_eval(item, np.asarray(arrays[f"waiting/{i}"], dtype=np.float32),
                                  int(row["generation"]), norm)
            self._waiting.append(item)

    # -- one generation ----------------------------------------------------------------------------
    def _tasks(self, params: np.ndarray, seeds: np.ndarray, g: int, record, obs_stats: bool = False):
        """Training rollout tasks of ``params`` ``(m, n)`` (``obs_stats``: their observations' sums too)."""
        return population_tasks(self.cfg.env, self.cfg.env_kwargs, self.spec, params, seeds,
                                self.executor.workers, g, record, self.cfg.rollout.max_steps,
                                expert=self.guide.expert, obs_norm=self.obs_norm(),
                                obs_stats=obs_stats and self.obs_stats is not None)

    def _submit_eval(self, item: _Row, theta: np.ndarray, g: int, obs_norm: ObsNorm | None) -> None:
        """Start generation ``g``'s test episodes of ``theta`` ``(n,)`` seeing observations through
        ``obs_norm`` (the normalizer of its training rollouts) for ``item``'s row."""
        E = self.cfg.rollout.test_episodes
        seeds = seeding.episode_seeds(self.cfg.seed, seeding.TEST, g, np.zeros(1), E)  # (1, E)
        item.theta, item.obs_norm = theta, obs_norm
        # rowwise: each episode's actions independent of how the E episodes are split over the workers
        # (one BLAS product over a chunk rounds by its size), so the test rewards are the same for any
        # executor and worker count -- and equal evaluate's on the same seeds
        item.tasks = policy_episode_tasks(self.cfg.env, self.cfg.env_kwargs, self.spec, theta, seeds,
                                          self.eval_executor.workers, g, self.cfg.rollout.max_steps,
                                          obs_norm=obs_norm, rowwise=True)
        item.futures = [self.eval_executor.submit(run_task, t) for t in item.tasks]

    def _collect(self, item: _Row) -> dict:
        """Finish a waiting row: gather its test episodes (``Executor.collect``: attempts lost with their
        worker, or still running ``task_timeout_s`` after this call, are rerun through ``map``, which
        retries) and update the best-so-far policy."""
        row = item.row
        if item.tasks:
            res = self.eval_executor.collect(run_task, item.tasks, item.futures)
            test_ret = np.concatenate([r.returns[0] for r in res])  # (E,)
            test_cpu = 0.0 if _in_process(self.eval_executor) else sum(r.cpu_time_s for r in res)
            self.c.cpu_time_s += test_cpu
            row["cpu_time_s"] += test_cpu
            row["test_reward_mean"], row["test_reward_std"] = float(test_ret.mean()), float(test_ret.std())
            row["test_env_steps"] = int(sum(r.lengths.sum() for r in res))
            if test_ret.mean() > self.c.best_test_reward:
                self.c.best_test_reward, self.best_params = float(test_ret.mean()), item.theta
                self.best_norm = item.obs_norm
                self.best_generation = int(row["generation"]) + 1
        row["test_reward_best_so_far"] = self.c.best_test_reward if math.isfinite(
            self.c.best_test_reward) else None
        return row

    def _drain(self) -> list[dict]:
        """Every waiting row, completed, in generation order."""
        rows = [self._collect(item) for item in self._waiting]
        self._waiting.clear()
        return rows

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
            xs = seeding.episode_seeds(cfg.seed, seeding.TRAIN, g, np.arange(P, P + k), E + x,
                                       cfg.rollout.common_seeds)  # (k, E + x)
            extra = self._tasks(X[P:], xs, g, record[P:])
            for t in extra:
                t.members = t.members + P  # population indices P .. P + k - 1
        if pre is not None:
            self.overlapped += 1
            # the population has been rolling out since the guide's clone began; the extras (the clone's
            # candidate, the babblers) could not start before it: their chunks as tasks of their own, one
            # a worker, queued behind the population's (in one call on one worker they were a serial tail:
            # UR5Reach-v0 idle, 2.53x a vanilla generation against 2.18x without the overlap)
            done = self.executor.map(run_task, extra) if extra else []
            results = self.executor.collect(run_task, tasks, pre.futures) + done
        elif fn is None and 0 < len(extra) <= len(tasks):
            # population chunk i and extras chunk i in one call, one lock-step loop (rollout.run_tasks: the
            # same results as apart), not a second wave of small tasks on the workers
            bundles = [[a] + extra[i : i + 1] for i, a in enumerate(tasks)]
            done = self.executor.map(run_tasks, bundles)
            results = [d[0] for d in done] + [d[1] for d in done if len(d) > 1]  # population, then extras
        else:
            results = self.executor.map(fn or run_task, tasks + extra)
        return results, time.perf_counter() - t_roll

    def _start_row(self, g: int, X: np.ndarray, fitness: np.ndarray, P: int) -> _Row:
        """Generation ``g``'s metrics row (train rewards of the population's ``fitness[:P]``); the test
        episodes of its best population member start when they are due. Every method tests by this one
        rule: the guide's extra members (candidates, babblers) are never tested; an accepted candidate
        becomes the mean and so the centre of the next population."""
        pop = fitness[:P]
        item = _Row({"generation": g, "env_steps": 0, "wall_time_s": 0.0, "cpu_time_s": 0.0,
                     "train_reward_mean": float(pop.mean()), "train_reward_max": float(pop.max()),
                     "train_reward_min": float(pop.min()), "test_reward_mean": None,
                     "test_reward_std": None, "test_reward_best_so_far": None, "test_env_steps": 0})
        cfg = self.cfg
        if cfg.rollout.test_episodes and (g % cfg.rollout.test_every == 0 or g == cfg.generations - 1):
            # the population's best member, with the normalizer it was trained with
            self._submit_eval(item, X[int(np.argmax(fitness[:P]))].copy(), g, self.obs_norm())
        return item

    def _end_row(self, g: int, item: _Row, results: list, old_mean: np.ndarray, extra: dict,
                 rollout_time: float, t0: float, cpu0: float) -> list[dict]:
        """Count generation ``g``'s env steps and CPU, fill in its row (``extra``: the guide's columns);
        returns the rows completed now (this one unless it waits for its test episodes)."""
        master_cpu = time.process_time() - cpu0
        steps = int(sum(r.lengths.sum() for r in results))
        # work done before generation 0 (the label probe): in its row's totals; a run resumed from a later
        # checkpoint has it in the counters already
        pre_steps, pre_s = self.guide.startup if g == 0 else (0, 0.0)
        self.guide.startup = (0, 0.0)
        self.c.env_steps += int(pre_steps)
        self.c.wall_time_s += float(pre_s)
        worker_cpu = sum(r.cpu_time_s for r in results)
        worker_cpu += float(extra.get("clone_cpu_time_s") or 0.0)  # shaped: cloning ran on the workers
        self.c.generation, self.c.env_steps = g + 1, self.c.env_steps + steps
        self.c.cpu_time_s += master_cpu + (0.0 if _in_process(self.executor) else worker_cpu)
        done, row = [], item.row
        if not self.cfg.eval_overlap:
            self._waiting.append(item)
            done += self._drain()
        row.update(env_steps=self.c.env_steps, gen_env_steps=steps, cpu_time_s=self.c.cpu_time_s,
                   gen_time_s=0.0, rollout_time_s=rollout_time,
                   update_norm=float(np.linalg.norm(np.asarray(self.strategy.mean) - old_mean)))
        row.update(extra)
        self.c.wall_time_s += time.perf_counter() - t0
        row.update(wall_time_s=self.c.wall_time_s, gen_time_s=time.perf_counter() - t0)
        if self.cfg.eval_overlap:
            self._waiting.append(item)
            if not item.tasks:  # nothing to wait for: written now, after the rows before it
                done += self._drain()
        return done

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
        if self._own_executor:
            if self.eval_executor is not self.executor:
                self.eval_executor.shutdown()
            self.executor.shutdown()


def _limit_torch_threads() -> None:
    import sys

    if "torch" in sys.modules:  # only the shaped method and TensorBoard load torch in the master
        sys.modules["torch"].set_num_threads(1)


def _jsonable(row: dict) -> dict:
    """A metrics row with plain Python numbers (numpy scalars are not JSON)."""
    return {k: (v.item() if isinstance(v, np.generic) else v) for k, v in row.items()}


def _non_finite(arrays: dict[str, np.ndarray]) -> list[str]:
    """The float arrays holding inf/NaN, the search's, the policies' and the guide's (M_phi, its
    normaliser, the learner): a checkpoint holds none."""
    return [k for k, v in arrays.items() if np.asarray(v).dtype.kind in "fc" and not np.isfinite(v).all()]


def _shaped(arrays: dict[str, np.ndarray], key: str, shape: tuple) -> np.ndarray:
    """``arrays[key]`` checked to have ``shape`` (``KeyError`` if missing, ``ValueError`` if not)."""
    v = np.asarray(arrays[key])
    if v.shape != shape:
        raise ValueError(f"{key} has shape {v.shape}, expected {shape}")
    return v


def _sub(arrays: dict[str, np.ndarray], prefix: str) -> dict[str, np.ndarray]:
    return {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}


def _in_process(executor: Executor) -> bool:
    return bool(getattr(executor, "in_process", False))


def _executor_options(cfg: RunConfig) -> dict:
    opts: dict = {"max_retries": cfg.max_retries, "task_timeout_s": cfg.task_timeout_s}
    if cfg.executor == "ray":
        opts["address"] = cfg.address
    return {k: v for k, v in opts.items() if v is not None or k == "task_timeout_s"}


__all__ = ["Trainer", "dump_config"]
