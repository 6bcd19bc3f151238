"""Environment throughput: the loop training runs (batched env step + MLP policy forward), all cores.

Each worker process builds the env's batched core with ``num_envs`` copies, resets them on distinct
seeds, and steps them with a random ``obs -> hidden -> hidden -> act`` tanh MLP per copy (one
population member per copy, as in training), re-resetting finished copies by restarting the batch
when all are done. After ``warmup_s`` (JIT, caches) it counts env-steps for ``seconds``. The figure is
the sum over processes of steps/s, with the median of ``repeats`` windows per process.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import platform
import time

import numpy as np


def _worker(args) -> dict:
    env_id, env_kwargs, num_envs, hidden, seconds, warmup_s, repeats, seed = args
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.envs.core import get_batch_core
    from shaped_es.policies import MLPSpec, forward
    from shaped_es.rollout import env_dims, make_env

    env = make_env(env_id, env_kwargs)
    core = get_batch_core(env)
    if core is None:
        raise SystemExit(f"{env_id} has no batched core (env.unwrapped.batch_core)")
    obs_dim, act_dim = env_dims(env)
    spec = MLPSpec(obs_dim, act_dim, hidden)
    rng = np.random.default_rng(seed)
    params = np.stack([spec.init(int(s)) for s in rng.integers(0, 2**31, num_envs)])  # (B, n)
    params += rng.normal(0, 0.5, params.shape).astype(np.float32)
    seeds = rng.integers(0, 2**31, num_envs)
    state, obs, _ = core.reset(seeds)
    alive = np.ones(num_envs, dtype=bool)

    def run_for(duration: float) -> tuple[int, float]:
        nonlocal state, obs, alive, seeds
        steps, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < duration:
            act = forward(spec, params, obs[:, None, :])[:, 0, :]  # (B,1,obs) -> (B, act)
            state, obs, _, term, trunc, _ = core.step(state, act)
            steps += int(alive.sum())
            alive &= ~(term | trunc)
            if not alive.any():
                seeds = seeds + 1
                state, obs, _ = core.reset(seeds)
                alive[:] = True
        return steps, time.perf_counter() - t0

    run_for(warmup_s)
    rates = []
    for _ in range(repeats):
        steps, dt = run_for(seconds / repeats)
        rates.append(steps / dt)
    return {"median": float(np.median(rates)), "rates": rates}


def bench_env(env_id: str, num_envs: int = 1024, workers: int | None = None, seconds: float = 6.0,
              warmup_s: float = 3.0, repeats: int = 5, hidden=(32, 32), env_kwargs=None) -> dict:
    workers = int(workers or os.cpu_count() or 1)
    args = [(env_id, env_kwargs or {}, num_envs, tuple(hidden), seconds, warmup_s, repeats, 1000 + i)
            for i in range(workers)]
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    if workers == 1:
        per = [_worker(args[0])]
    else:
        with mp.get_context("spawn").Pool(workers) as pool:
            per = pool.map(_worker, args)
    return {
        "env": env_id,
        "num_envs": num_envs,
        "workers": workers,
        "policy": f"{'-'.join(map(str, hidden))} tanh MLP per env",
        "steps_per_second": round(sum(p["median"] for p in per), 1),
        "per_worker_steps_per_second": [round(p["median"], 1) for p in per],
        "seconds": seconds,
        "machine": f"{platform.machine()} {os.cpu_count()} cores",
    }
