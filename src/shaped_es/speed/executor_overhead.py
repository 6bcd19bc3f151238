"""Executor overhead: one ES generation's rollouts (population 64, the paper's size) on each executor.

For every executor the population is split into one task per worker, exactly as the trainer does, and
each generation's ``map(run_task, tasks)`` is timed (after ``warmup`` untimed generations: pool start,
JIT, env construction). Two views of the cost beyond the rollouts themselves, per generation:

- ``overhead_s``: generation wall time minus the slowest task's own wall time (the critical path),
  i.e. what placing tasks and moving parameters and results costs;
- ``noop_map_s``: wall time of a map over tasks of the same size whose function returns at once.

Figures are medians over ``generations``. ``python -m shaped_es.speed.executor_overhead`` prints
the JSON. MPI as root needs Open MPI's ``*_ALLOW_RUN_AS_ROOT*`` variables (see ``executors/mpi_executor``).
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import time
from dataclasses import dataclass

import numpy as np

from shaped_es import seeding
from shaped_es.executors import ExecutorError, make_executor
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutResult, RolloutTask, env_dims, make_env, run_task


@dataclass
class Timed:
    result: RolloutResult | None
    wall_s: float  # the task's own wall time in its worker


def timed_run(task: RolloutTask) -> Timed:
    t0 = time.perf_counter()
    out = run_task(task)
    return Timed(out, time.perf_counter() - t0)


def noop(task: RolloutTask) -> Timed:
    return Timed(None, 0.0)


def default_env() -> str:
    """CarNav-v0 (the built-in waypoint env) when it can be made, else CartPole-v1."""
    import shaped_es.envs  # noqa: F401 - registers the built-in envs

    try:
        make_env("CarNav-v0").close()
        return "CarNav-v0"
    except Exception:  # noqa: BLE001 - any failure: fall back to a stock env
        return "CartPole-v1"


def _tasks(env_id, spec, params, g, workers, max_steps):
    P = params.shape[0]
    seeds = seeding.episode_seeds(0, seeding.TRAIN, g, np.arange(P), 2)  # (P, E=2)
    return [
        RolloutTask(env_id, {}, spec, params[idx], idx, seeds[idx], generation=g, max_steps=max_steps)
        for idx in np.array_split(np.arange(P), max(1, min(P, workers)))
    ]


def _bench_one(name, env_id, spec, params, workers, generations, warmup, max_steps) -> dict:
    ex = make_executor(name, workers=workers, max_retries=0, task_timeout_s=None)
    try:
        gen, over, noop_s, steps = [], [], [], 0
        for g in range(warmup + generations):
            tasks = _tasks(env_id, spec, params, g, ex.workers, max_steps)
            t0 = time.perf_counter()
            res = ex.map(timed_run, tasks)
            wall = time.perf_counter() - t0
            t0 = time.perf_counter()
            ex.map(noop, tasks)
            nwall = time.perf_counter() - t0
            if g >= warmup:
                gen.append(wall)
                over.append(wall - max(r.wall_s for r in res))
                noop_s.append(nwall)
                steps += int(sum(r.result.lengths.sum() for r in res))
        return {
            "workers": ex.workers,
            "generation_s": round(statistics.median(gen), 4),
            "overhead_s": round(statistics.median(over), 4),
            "noop_map_s": round(statistics.median(noop_s), 4),
            "env_steps_per_generation": steps // generations,
        }
    finally:
        ex.shutdown()


def bench_executors(executors=("process", "ray", "mpi"), env_id: str | None = None, pairs: int = 32,
                    hidden=(32, 32), workers: int | None = None, generations: int = 5, warmup: int = 1,
                    max_steps: int | None = None) -> dict:
    """Median generation time and overhead per executor; an executor that cannot start reports why."""
    env_id = env_id or default_env()
    env = make_env(env_id)
    spec = MLPSpec(*env_dims(env), tuple(hidden))
    env.close()
    rng = np.random.default_rng(0)
    P = 2 * pairs
    params = (spec.init(0)[None] + rng.normal(0, 0.1, (P, spec.num_params))).astype(np.float32)  # (P, n)
    out: dict = {"env": env_id, "population": P, "num_params": spec.num_params,
                 "workers": int(workers or os.cpu_count() or 1), "generations": generations,
                 "machine": f"{platform.machine()} {os.cpu_count()} cores", "executors": {}}
    for name in executors:
        try:
            out["executors"][name] = _bench_one(name, env_id, spec, params, out["workers"], generations,
                                                warmup, max_steps)
        except ExecutorError as exc:
            out["executors"][name] = {"error": str(exc)}
    return out


def main() -> None:
    # Import by name so task functions pickle as ``shaped_es.speed...``, not ``__main__``.
    from shaped_es.speed.executor_overhead import bench_executors as bench

    print(json.dumps(bench(), indent=2))


if __name__ == "__main__":
    main()
