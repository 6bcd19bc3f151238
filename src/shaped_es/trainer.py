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

A checkpoint holds the strategy's and the guide's state; ``resume`` reloads the newest one, drops
metrics rows written after it, and continues, giving the rows an uninterrupted run would have given.
"""

from __future__ import annotations

import contextlib
import math
import time
from concurrent.futures import Future
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from shaped_es import seeding
from shaped_es.config import RunConfig, dump_config
from shaped_es.executors import Executor, make_executor
from shaped_es.methods import METHODS, resolve
from shaped_es.policies import MLPSpec
from shaped_es.progress import ProgressDisplay
from shaped_es.rollout import policy_episode_tasks, policy_spec, population_tasks, run_task
from shaped_es.run_meta import Counters, config_digest
from shaped_es.store import RunStore, StoreError
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


def build_guide(cfg: RunConfig, spec: MLPSpec, store: RunStore):
    """The guide of ``cfg.method`` (its entry in :data:`methods.METHODS`)."""
    method = METHODS[cfg.method]
    return resolve(method.guide)(**method.guide_args(cfg, spec, store))


def train(cfg: RunConfig, store: RunStore, progress: bool = True) -> list[dict]:
    """Train (or resume) an ES run into ``store``; returns the metrics rows written (``Trainer.run``)."""
    return Trainer(cfg, store, progress=progress).run()


@dataclass
class _Row:
    """A metrics row waiting for its generation's test episodes (``futures`` empty: none due)."""

    row: dict
    theta: np.ndarray | None = None
    tasks: list = field(default_factory=list)
    futures: list[Future] = field(default_factory=list)


class Trainer:
    def __init__(self, cfg: RunConfig, store: RunStore, executor: Executor | None = None,
                 progress: bool = True):
        self.cfg, self.store, self.progress = cfg, store, progress
        self._own_executor = executor is None
        self.executor = executor or make_executor(
            cfg.executor, workers=cfg.workers, **_executor_options(cfg)
        )
        self.eval_executor = self.executor
        if cfg.eval_workers and cfg.executor == "process" and self._own_executor:
            self.eval_executor = make_executor("process", workers=cfg.eval_workers,
                                               **_executor_options(cfg))
        self._waiting: list[_Row] = []  # rows of finished generations, in order, awaiting test results
        self.spec = policy_spec(cfg)
        x0 = self.spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
        self.strategy = build_strategy(cfg, x0)
        self.guide = build_guide(cfg, self.spec, store)
        self.c = Counters()
        self.best_params = np.asarray(self.strategy.mean, dtype=np.float32).copy()
        self._tb = None

    # -- checkpointing -----------------------------------------------------------------------------
    def _checkpoint(self) -> None:
        arrays = {f"strategy/{k}": v for k, v in self.strategy.state_dict().items()}
        arrays |= {f"guide/{k}": v for k, v in self.guide.state_dict().items()}
        arrays["policy/best"] = self.best_params
        arrays["policy/mean"] = np.asarray(self.strategy.mean, dtype=np.float32)
        meta = {**self.c.__dict__, "config_digest": config_digest(self.cfg), "method": self.cfg.method,
                "policy": {"obs_dim": self.spec.obs_dim, "act_dim": self.spec.act_dim,
                           "hidden": list(self.spec.hidden)}}
        if not math.isfinite(meta["best_test_reward"]):
            meta["best_test_reward"] = None
        # Rows whose test episodes are still running: resume submits them again (same seeds).
        meta["waiting_rows"] = [_jsonable(item.row) for item in self._waiting]
        for i, item in enumerate(self._waiting):
            if item.theta is not None:
                arrays[f"waiting/{i}"] = item.theta
        bad = [k for k, v in arrays.items() if k.startswith(("strategy/", "policy/", "waiting/"))
               and np.asarray(v).dtype.kind == "f" and not np.isfinite(v).all()]
        if bad:  # never save a state a resume could not continue from; the previous one stays
            raise DivergedError(self._diverged(self.c.generation - 1, f"the state to checkpoint ({bad[0]})"))
        self.store.save_checkpoint(self.c.generation, arrays, meta, keep=self.cfg.keep_checkpoints)
        after = getattr(self.guide, "after_checkpoint", None)
        if after is not None:  # the checkpoint is durable: what only older ones needed may go
            after(self.c.generation)

    def _diverged(self, g: int, what: str) -> str:
        gens = self.store.checkpoints()
        kept = f"generation {gens[-1]}" if gens else "none yet"
        knobs = "es.sigma / es.lr" + (" / shaping.eta" if self.cfg.method == "shaped" else "")
        return (f"generation {g}: {what} became non-finite (inf/NaN); the run stopped, its last good "
                f"checkpoint ({kept}) is kept; lower {knobs}")

    def restore(self) -> bool:
        """Load the newest complete checkpoint if any (whatever ``latest.json`` says), after checking it
        belongs to this run; then ``RunStore.recover`` deletes what a killed run left and drops the
        metrics rows past the checkpoint. Returns True if one was loaded. Nothing on disk changes when
        the checkpoint does not fit."""
        loaded = self.store.load_checkpoint()
        if loaded is None:
            self.store.recover(loaded=None)
            return False
        arrays, meta = loaded
        where = f"checkpoint gen_{meta['generation']:06d} in {self.store.ckpt_dir}"
        if meta.get("method", self.cfg.method) != self.cfg.method or \
                meta.get("config_digest") != config_digest(self.cfg):
            raise StoreError(f"{where} was made with a different config")
        waiting = meta.get("waiting_rows", [])
        try:
            if not isinstance(waiting, list) or not all(
                    isinstance(r, dict) and type(r.get("generation")) is int for r in waiting):
                raise ValueError("malformed waiting_rows")
            counters = {k: meta[k] for k in Counters.__dataclass_fields__}
            for k, v in counters.items():
                if not (v is None and k == "best_test_reward") and (
                        isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)):
                    raise ValueError(f"counter {k}={v!r}")
            if counters["generation"] != meta["generation"]:
                raise ValueError("counter generation differs from the checkpoint's")
            self.strategy.load_state_dict(_sub(arrays, "strategy/"))
            self.guide.load_state_dict(_sub(arrays, "guide/"))
            self.best_params = arrays["policy/best"]
            if np.shape(self.best_params) != (self.spec.num_params,):
                raise ValueError(f"policy/best has shape {np.shape(self.best_params)}")
        except (KeyError, ValueError, TypeError, IndexError) as exc:
            msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            msg = f"it lacks {msg}" if isinstance(exc, KeyError) else msg
            raise StoreError(f"{where} does not fit this run: {msg}") from None
        self.store.recover(loaded=loaded)
        for k, v in counters.items():
            setattr(self.c, k, v if v is not None else -math.inf)
        self._waiting = []
        for i, row in enumerate(waiting):
            item = _Row(dict(row))
            if f"waiting/{i}" in arrays:
                self._submit_eval(item, np.asarray(arrays[f"waiting/{i}"], dtype=np.float32),
                                  int(row["generation"]))
            self._waiting.append(item)
        # Rows after the checkpoint's last written one are dropped; waiting rows are written again.
        written = [int(i.row["generation"]) for i in self._waiting] or [self.c.generation]
        self.store.truncate_metrics(min(written) - 1)
        return True

    # -- one generation ----------------------------------------------------------------------------
    def _tasks(self, params: np.ndarray, seeds: np.ndarray, g: int, record: bool):
        return population_tasks(self.cfg.env, self.cfg.env_kwargs, self.spec, params, seeds,
                                self.executor.workers, g, record, self.cfg.rollout.max_steps)

    def _submit_eval(self, item: _Row, theta: np.ndarray, g: int) -> None:
        """Start generation ``g``'s test episodes of ``theta`` ``(n,)`` for ``item``'s row."""
        E = self.cfg.rollout.test_episodes
        seeds = seeding.episode_seeds(self.cfg.seed, seeding.TEST, g, np.zeros(1), E)  # (1, E)
        item.theta = theta
        item.tasks = policy_episode_tasks(self.cfg.env, self.cfg.env_kwargs, self.spec, theta, seeds,
                                          self.eval_executor.workers, g, self.cfg.rollout.max_steps)
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
        cfg = self.cfg
        X = np.asarray(self.strategy.ask(), dtype=np.float32)  # (P, n)
        P = X.shape[0]
        members = np.arange(P)
        seeds = seeding.episode_seeds(cfg.seed, seeding.TRAIN, g, members, cfg.rollout.episodes,
                                      cfg.rollout.common_seeds)  # (P, E)
        self.guide.begin_generation(g)
        fn = self.guide.rollout_fn() or run_task
        t_roll = time.perf_counter()
        results = self.executor.map(fn, self._tasks(X, seeds, g, self.guide.record))
        rollout_time = time.perf_counter() - t_roll
        done = self._drain()  # the previous generation's test episodes ran alongside these rollouts
        returns = np.concatenate([r.returns for r in results])  # (P, E) in member order
        fitness = returns.mean(axis=1)  # (P,) mean over the member's episodes (paper: 2 seeds)
        steps = int(sum(r.lengths.sum() for r in results))
        worker_cpu = sum(r.cpu_time_s for r in results)
        item = _Row({"generation": g, "env_steps": 0, "wall_time_s": 0.0, "cpu_time_s": 0.0,
                     "train_reward_mean": float(fitness.mean()), "train_reward_max": float(fitness.max()),
                     "train_reward_min": float(fitness.min()), "test_reward_mean": None,
                     "test_reward_std": None, "test_reward_best_so_far": None, "test_env_steps": 0})
        if cfg.rollout.test_episodes and (g % cfg.rollout.test_every == 0 or g == cfg.generations - 1):
            self._submit_eval(item, X[int(np.argmax(fitness))].copy(), g)  # the generation's best member
        old_mean = np.array(self.strategy.mean, copy=True)
        self.strategy.tell(fitness)
        extra = self.guide.after_tell(g, X, results, old_mean, self.strategy, self.executor.map)
        if not np.isfinite(self.strategy.mean).all():  # nothing of generation g is written
            raise DivergedError(self._diverged(g, "the search mean"))
        worker_cpu += float(extra.get("clone_cpu_time_s") or 0.0)  # shaped: cloning ran on the workers
        master_cpu = time.process_time() - cpu0
        self.c.generation, self.c.env_steps = g + 1, self.c.env_steps + steps
        self.c.cpu_time_s += master_cpu + (0.0 if _in_process(self.executor) else worker_cpu)
        row = item.row
        if not cfg.eval_overlap:
            self._waiting.append(item)
            done += self._drain()
        row.update(env_steps=self.c.env_steps, gen_env_steps=steps, cpu_time_s=self.c.cpu_time_s,
                   gen_time_s=0.0, rollout_time_s=rollout_time,
                   update_norm=float(np.linalg.norm(np.asarray(self.strategy.mean) - old_mean)))
        row.update(extra)
        self.c.wall_time_s += time.perf_counter() - t0
        row.update(wall_time_s=self.c.wall_time_s, gen_time_s=time.perf_counter() - t0)
        if cfg.eval_overlap:
            self._waiting.append(item)
            if not item.tasks:  # nothing to wait for: written now, after the rows before it
                done += self._drain()
        return done

    def run(self) -> list[dict]:
        """Run (or continue) to ``cfg.generations``; returns the rows written by this call."""
        # The master's linear algebra is small (QR of (n, k), M_phi minibatches): one thread avoids
        # oversubscribing the cores the workers use (multi-threaded BLAS was 100x slower here).
        with contextlib.ExitStack() as stack:
            try:  # one writer per run directory (StoreError naming the holder otherwise)
                stack.enter_context(self.store.lock())
            except BaseException:
                self.close()
                raise
            with threadpool_limits(limits=1):
                return self._run()

    def _run(self) -> list[dict]:
        _limit_torch_threads()
        self.restore()
        rows: list[dict] = []
        bar = ProgressDisplay(self.cfg.generations, self.c.generation, enabled=self.progress)
        try:
            for g in range(self.c.generation, self.cfg.generations):
                done = self.step(g)
                last = g + 1 == self.cfg.generations
                if last:
                    done += self._drain()
                for row in done:
                    self.store.append_metrics(row)
                    self._log_tb(row)
                    rows.append(row)
                    bar.update(int(row["generation"]), row)
                if (g + 1) % self.cfg.checkpoint_every == 0 or last:
                    self._checkpoint()
        finally:
            bar.close()
            self.close()
        return rows

    def _log_tb(self, row: dict) -> None:
        """The row as TensorBoard scalars ``train/``, ``test/``, ``shaping/``, ``time/``, ``misc/`` at
        step ``row["env_steps"]`` (:mod:`shaped_es.tblog`)."""
        if not self.cfg.tensorboard:
            return
        from shaped_es import tblog

        if self._tb is None:
            self._tb = tblog.open_writer(self.store.root / "tb", row)
        tblog.log_row(self._tb, row)

    def close(self) -> None:
        if self._tb is not None:
            self._tb.close()
            self._tb = None
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
