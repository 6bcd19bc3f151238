"""Environment throughput: the loop training runs (env step + batched MLP policy forward), all cores.

Each worker process makes ``num_envs`` copies of the env, resets them on distinct seeds, and steps them
with a random ``obs -> hidden -> hidden -> act`` tanh MLP per copy (one population member per copy, as in
training), as the rollout layer does: an env with a batched core (``env.unwrapped.batch_core``) steps all
copies in one call, restarting the batch when all are done; any other Gymnasium env is one instance per
copy, stepped one after another each step (one batched policy forward), each copy reset when its episode
ends (an env whose instances share one simulator, ``serial_episodes``, runs one copy). After ``warmup_s``
(JIT, caches) it counts env-steps for ``seconds``. The figure is the sum over processes of steps/s, with
the median of ``repeats`` windows per process.
"""

from __future__ import annotations

import os
import platform
import time
import traceback
from concurrent.futures import ProcessPoolExecutor
from multiprocessing import get_context

import numpy as np

from shaped_es.env_probe import EnvError, observation, reset_output, step_output
from shaped_es.actions import _to_env_action

BATCHED_LOOP = "batched core"
GYM_LOOP = "gymnasium, one env per copy"


class _BatchedSteps:
    """The copies stepped by the env's batched core; finished copies wait until all are done."""

    loop = BATCHED_LOOP

    def __init__(self, core, seeds: np.ndarray):
        self.core, self.seeds = core, seeds
        self.state, self.obs, _ = core.reset(seeds)
        self.alive = np.ones(len(seeds), dtype=bool)

    def step(self, act: np.ndarray) -> int:
        self.state, self.obs, _, term, trunc, _ = self.core.step(self.state, act)
        n = int(self.alive.sum())
        self.alive &= ~(term | trunc)
        if not self.alive.any():
            self.seeds = self.seeds + 1
            self.state, self.obs, _ = self.core.reset(self.seeds)
            self.alive[:] = True
        return n


class _GymSteps:
    """One Gymnasium env per copy, stepped in turn; a copy whose episode ends is reset on a new seed."""

    loop = GYM_LOOP

    def __init__(self, envs: list, seeds: np.ndarray):
        self.envs, self.seeds = envs, seeds
        self.shape = tuple(envs[0].observation_space.shape)
        self.obs = np.stack([observation(reset_output(e.reset(seed=int(s)))[0], self.shape)
                             for e, s in zip(envs, seeds)])  # (B, obs)

    def step(self, act: np.ndarray) -> int:
        for b, env in enumerate(self.envs):
            o, _, term, trunc, _ = step_output(env.step(_to_env_action(env.action_space, act[b])))
            if term or trunc:
                self.seeds[b] += len(self.envs)
                o = reset_output(env.reset(seed=int(self.seeds[b])))[0]
            self.obs[b] = observation(o, self.shape)
        return len(self.envs)


def _worker(args) -> dict:
    """One process's figure; an env's ``sys.exit`` comes back as one :class:`EnvError` (a pool worker that
    exits would leave the command without its result or an error line)."""
    try:
        return _measure(*args)
    except SystemExit as exc:
        raise EnvError(f"env {args[0]!r} called sys.exit({exc.code!r}) while its speed was measured; an env "
                       f"reports a failure by raising an exception", traceback.format_exc()) from None


def _measure(env_id, env_kwargs, num_envs, hidden, seconds, warmup_s, repeats, seed) -> dict:
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.envs.core import get_batch_core, runs_serially
    from shaped_es.policies import MLPSpec, forward
    from shaped_es.rollout import env_dims, make_env

    env = make_env(env_id, env_kwargs)
    core = get_batch_core(env)
    if core is None and runs_serially(env):
        num_envs = 1  # its instances in one process share one simulator: one episode at a time
    obs_dim, act_dim = env_dims(env)
    spec = MLPSpec(obs_dim, act_dim, hidden)
    rng = np.random.default_rng(seed)
    params = np.stack([spec.init(int(s)) for s in rng.integers(0, 2**31, num_envs)])  # (B, n)
    params += rng.normal(0, 0.5, params.shape).astype(np.float32)
    seeds = rng.integers(0, 2**31, num_envs)
    if core is not None:
        steps_of = _BatchedSteps(core, seeds)
    else:
        steps_of = _GymSteps([env] + [make_env(env_id, env_kwargs) for _ in range(num_envs - 1)], seeds)

    def run_for(duration: float) -> tuple[int, float]:
        steps, t0 = 0, time.perf_counter()
        while time.perf_counter() - t0 < duration:
            act = forward(spec, params, steps_of.obs[:, None, :])[:, 0, :]  # (B,1,obs) -> (B, act)
            steps += steps_of.step(act)
        return steps, time.perf_counter() - t0

    run_for(warmup_s)
    rates = []
    for _ in range(repeats):
        steps, dt = run_for(seconds / repeats)
        rates.append(steps / dt)
    return {"median": float(np.median(rates)), "rates": rates, "loop": steps_of.loop, "num_envs": num_envs}


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
        # not multiprocessing.Pool: a worker that exits or dies there leaves pool.map waiting forever;
        # here its exception (SystemExit included) comes back, and a dead worker is BrokenProcessPool
        with ProcessPoolExecutor(workers, mp_context=get_context("spawn")) as pool:
            per = list(pool.map(_worker, args))
    return {
        "env": env_id,
        "num_envs": per[0]["num_envs"],
        "workers": workers,
        "loop": per[0]["loop"],
        "policy": f"{'-'.join(map(str, hidden))} tanh MLP per env",
        "steps_per_second": round(sum(p["median"] for p in per), 1),
        "per_worker_steps_per_second": [round(p["median"], 1) for p in per],
        "seconds": seconds,
        "machine": f"{platform.machine()} {os.cpu_count()} cores",
    }
