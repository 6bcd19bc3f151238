"""Evaluate a run's saved policy on fresh test episodes (``shaped-es evaluate RUN --episodes 15``).

The JSON names the policy's own generation (``policy_generation``: for ``best``, the generations done
when its test episodes made it the best; ``checkpoint_generations``: the checkpoint it is read from) and
the episode seeds (``episode_seeds``, also ``shaped_es.evaluation_seeds``): ``env.reset(seed=s)`` with
each, driven by ``load_policy(RUN).predict``, gives the returns reported here."""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.config import check_seed
from shaped_es.executors import make_executor
from shaped_es.methods import METHODS, resolve
from shaped_es.trained.load import es_obs_norm, es_params, policy_generation
from shaped_es.rollout import policy_episode_tasks, policy_spec, probe_env, run_task, warn_if_endless
from shaped_es.rundir.store import RunStore, StoreError


def evaluate_run(run_dir, episodes: int = 15, which: str = "best", seed: int = 12345,
                 executor: str = "process", workers: int | None = None) -> dict:
    if episodes <= 0:
        raise StoreError("--episodes must be positive")
    check_seed(seed)
    store = RunStore(run_dir)
    cfg = store.read_config()
    arrays, meta = store.require_checkpoint()
    seeds = np.array(seeding.evaluation_seeds(episodes, seed))  # (E,)
    returns = resolve(METHODS[cfg.method].evaluate)(cfg, arrays, which, seeds, run_dir, executor, workers)
    return _summary(store, which, meta, returns, seeds)


def es_returns(cfg, arrays: dict, which: str, seeds: np.ndarray, run_dir, executor: str,
               workers: int | None) -> np.ndarray:
    """Returns ``(E,)`` of an ES checkpoint's ``which`` policy on the episodes ``seeds`` ``(E,)``, spread
    over the executor's workers, each row of the policy computed on its own (``load_policy``'s actions)."""
    probe = probe_env(cfg.env, cfg.env_kwargs)
    spec = policy_spec(cfg, probe)
    theta = es_params(arrays, which, spec.num_params, run_dir)
    norm = es_obs_norm(arrays, which, spec.obs_dim, run_dir)  # es.obs_norm: what the policy saw (or None)
    warn_if_endless(cfg.env, probe, cfg.rollout.max_steps)
    with make_executor(executor, workers=workers) as ex:
        tasks = policy_episode_tasks(cfg.env, cfg.env_kwargs, spec, theta, seeds[None], ex.workers,
                                     max_steps=cfg.rollout.max_steps, rowwise=True, obs_norm=norm)  # seeds (1, E)
        res = ex.map(run_task, tasks)
    return np.concatenate([r.returns[0] for r in res])  # (E,)


def _summary(store: RunStore, which: str, meta: dict, returns: np.ndarray, seeds: np.ndarray) -> dict:
    return {"run_dir": str(store.root), "policy": which,
            "policy_generation": policy_generation(store, meta, which),  # best: when it was found
            "checkpoint_generations": meta["generation"],  # the generations the checkpoint covers
            "episodes": int(len(returns)), "reward_mean": float(returns.mean()),
            "reward_std": float(returns.std()), "reward_min": float(returns.min()),
            "reward_max": float(returns.max()), "episode_returns": [float(r) for r in returns],
            "episode_seeds": [int(s) for s in seeds]}
