"""Evaluate a run's saved policy on fresh test episodes (``shaped-es evaluate RUN --episodes 15``).

The JSON names the policy's own generation (``policy_generation``: for ``best``, the generations done
when its test episodes made it the best; ``checkpoint_generations``: the checkpoint it is read from) and
the episode seeds (``episode_seeds``, also ``shaped_es.evaluation_seeds``): ``env.reset(seed=s)`` with
each, driven by ``load_policy(RUN).predict``, gives the returns reported here."""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.config import ConfigError, check_seed
from shaped_es.executors import make_executor
from shaped_es.methods import METHODS, resolve
from shaped_es.trained.load import es_obs_norm, es_params, policy_generation
from shaped_es.rollout import policy_episode_tasks, policy_spec, probe_env, run_task, warn_if_endless
from shaped_es.rundir.store import RunStore, StoreError


def evaluate_run(run_dir, episodes: int = 15, which: str = "best", seed: int = 12345,
                 executor: str = "process", workers: int | None = None) -> dict:
    if episodes <= 0:
        raise StoreError("--episodes must be positive")
    if workers is not None and workers <= 0:
        raise ConfigError(f"--workers must be positive, got {workers}")
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
        # during: an env's error names evaluate, not a generation (evaluate runs none)
        tasks = policy_episode_tasks(cfg.env, cfg.env_kwargs, spec, theta, seeds[None], ex.workers,
                                     max_steps=cfg.rollout.max_steps, rowwise=True, obs_norm=norm,
                                     during=f"evaluate, the {which} policy")  # seeds (1, E)
        res = ex.map(run_task, tasks)
    return np.concatenate([r.returns[0] for r in res])  # (E,)


def selection_note(store: RunStore, result: dict) -> str | None:
    """For ``best``: one line where its fresh episodes ``result`` (``evaluate_run``'s) score below the test reward
    that made it the best by more than 2 standard errors of their mean. That test reward is the highest of the
    run's noisy test means, so it reads high where episodes differ (a new user's slipping drive: chosen at 9.16,
    6.90 on 15 new episodes, with the final mean above the best on 50); None where it does not, or for ``mean``. Where
    no test has chosen one yet (a run stopped between its first checkpoint and its first test's row), that it is the
    starting policy (a new user's evaluate said nothing)."""
    best, r = result.get("test_reward_when_chosen"), np.asarray(result["episode_returns"], np.float64)  # (E,)
    if result["policy"] == "best" and best is None:  # a run stopped after a checkpoint, before its first test's row
        return ("note: no test of this run has chosen a best policy yet (its checkpoint came before the first test "
                "result): this is the policy the run started from")
    if result["policy"] != "best" or r.size < 2:
        return None
    se = float(r.std(ddof=1) / np.sqrt(r.size))
    if not r.mean() < best - 2 * se:
        return None
    tests = sum(row.get("test_reward_mean") not in (None, "") for row in store.read_metrics())
    where = f" at generation {result['policy_generation']}" if result.get("policy_generation") is not None else ""
    return (f"note: the best policy's test reward {best:.2f}{where} is the highest of the run's {tests} test "
            f"means; on these {r.size} new episodes it scores {r.mean():.2f} +- {2 * se:.2f} (2 standard errors): "
            f"the highest of many noisy tests reads high where episodes differ. --policy mean evaluates the "
            f"search's final mean; more --episodes narrow both")


def _summary(store: RunStore, which: str, meta: dict, returns: np.ndarray, seeds: np.ndarray) -> dict:
    chosen = meta.get("best_test_reward") if which == "best" else None
    return {"run_dir": str(store.root), "policy": which,
            "test_reward_when_chosen": None if chosen is None else float(chosen),  # best: the test that chose it
            "policy_generation": policy_generation(store, meta, which),  # best: when it was found
            "checkpoint_generations": meta["generation"],  # the generations the checkpoint covers
            "episodes": int(len(returns)), "reward_mean": float(returns.mean()),
            "reward_std": float(returns.std()), "reward_min": float(returns.min()),
            "reward_max": float(returns.max()), "episode_returns": [float(r) for r in returns],
            "episode_seeds": [int(s) for s in seeds]}
