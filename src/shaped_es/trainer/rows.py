"""A generation's metrics row and its test episodes (``eval_overlap``: collected a generation later):
the row started once the population's returns are known, the tested policy's episodes submitted,
the row finished with the generation's counts and times, and completed rows handed back in order.

:class:`Rows` is :class:`~shaped_es.trainer.Trainer`'s part that does this.
"""

from __future__ import annotations

import math
import time
from concurrent.futures import Future
from dataclasses import dataclass, field

import numpy as np

from shaped_es import seeding
from shaped_es.executors import Executor
from shaped_es.guides.mechanisms import CHECK_METRIC
from shaped_es.policies import ObsNorm
from shaped_es.rollout import policy_episode_tasks, run_task

TIME_COLUMNS = ("wall_time_s", "cpu_time_s", "gen_time_s", "rollout_time_s", "clone_cpu_time_s")


@dataclass
class _Row:
    """A metrics row waiting for its generation's test episodes (``futures`` empty: none due)."""

    row: dict
    theta: np.ndarray | None = None
    obs_norm: ObsNorm | None = None  # the normalizer theta's test episodes run with (es.obs_norm)
    tasks: list = field(default_factory=list)
    futures: list[Future] = field(default_factory=list)


class Rows:
    """The metrics rows of :class:`~shaped_es.trainer.Trainer` (its ``_waiting`` rows, ``eval_executor``,
    counters ``c``, best policy)."""

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

    def _start_row(self, g: int, X: np.ndarray, fitness: np.ndarray, P: int) -> _Row:
        """Generation ``g``'s metrics row (train rewards of the population's ``fitness[:P]``); the test
        episodes of its tested policy start when they are due. Every method tests by the one rule the config
        names (``rollout.test_policy``): ``best``, the population member with the highest training return;
        ``mean``, the search's mean whose population this generation sampled (before its update). The
        guide's extra members (candidates, babblers) are never tested; an accepted candidate becomes the
        mean, and so the next generation's tested policy under ``mean``."""
        pop = fitness[:P]
        item = _Row({"generation": g, "env_steps": 0, "wall_time_s": 0.0, "cpu_time_s": 0.0,
                     "train_reward_mean": float(pop.mean()), "train_reward_max": float(pop.max()),
                     "train_reward_min": float(pop.min()), "test_reward_mean": None,
                     "test_reward_std": None, "test_reward_best_so_far": None, "test_env_steps": 0})
        cfg = self.cfg
        if cfg.rollout.test_episodes and (g % cfg.rollout.test_every == 0 or g == cfg.generations - 1):
            if cfg.rollout.test_policy == "mean":  # the centre of this generation's population
                theta = np.asarray(self.strategy.mean, np.float32).copy()
            else:  # the population's best member
                theta = X[int(np.argmax(fitness[:P]))].copy()
            self._submit_eval(item, theta, g, self.obs_norm())  # with the normalizer it was trained with
        return item

    def _end_row(self, g: int, item: _Row, results: list, old_mean: np.ndarray, extra: dict,
                 rollout_time: float, t0: float, cpu0: float) -> list[dict]:
        """Count generation ``g``'s env steps and CPU, fill in its row (``extra``: the guide's columns);
        returns the rows completed now (this one unless it waits for its test episodes)."""
        master_cpu = time.process_time() - cpu0
        steps = int(sum(r.lengths.sum() for r in results))
        steps += int(extra.get(CHECK_METRIC) or 0)  # the guide's own episodes (a candidate's check)
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


def _in_process(executor: Executor) -> bool:
    return bool(getattr(executor, "in_process", False))
