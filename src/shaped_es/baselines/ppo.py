"""PPO baseline (Stable-Baselines3) on the same envs and seeds, logged in the ES methods' metrics format.

The paper compares its shaped ES with PPO "on a single core" and plots PPO against CPU time (Fig. 4):
the run sets ``torch.set_num_threads(1)`` and steps its ``n_envs`` envs in this one process.

A "generation" is the whole number of PPO iterations (collect ``n_steps * n_envs`` env steps, then
``n_epochs`` of minibatch updates) nearest to the most env steps one ES generation can use (see
``ppo_settings.py``); it writes one ``metrics.csv`` row with the ES trainer's columns, so
``cfg.generations`` maps to a total budget of ``generations * gen_env_steps`` env steps.

- ``train_reward_*``: returns of the training episodes that finished during the generation (stochastic
  policy; SB3's ``Monitor`` episode records, the same records SB3's ``ep_info_buffer`` holds), falling
  back to that buffer (last 100 episodes) when none finished.
- ``test_reward_*``: the deterministic policy on the TEST episode seeds the ES trainer gives its best
  member at generation ``g`` (``seeding.episode_seeds(seed, TEST, g, [0], E)``), every
  ``rollout.test_every`` generations and at the last one.
- ``rollout_time_s``: time spent collecting rollouts (the rest of ``gen_time_s``: updates and tests).
- ``update_norm``: norm of the change of the actor's parameters over the generation.

Resume: checkpoints hold the policy, the best policy, Adam's moments and torch's RNG as arrays
(``ppo_state.py``); SB3's own ``save`` (a zip of pickles) is never used. A resumed run restarts the
training episodes in progress (their env state is not saved: the envs are reseeded from the root seed
and the generation) and refills the rollout buffer, so it is close to, not bit-identical with, an
uninterrupted run; metrics rows after the checkpoint are dropped as for ES.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict

import numpy as np
import torch
from gymnasium.wrappers import TimeLimit
from stable_baselines3 import PPO
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.monitor import Monitor
from stable_baselines3.common.vec_env import DummyVecEnv

from shaped_es import seeding
from shaped_es.baselines.ppo_settings import PPOSettings, iterations_per_generation, ppo_settings
from shaped_es.baselines.ppo_state import (BEST, POLICY, RNG, DeterministicEpisodes, actor_vector, copy_state,
                                           from_arrays, optimizer_from_arrays, optimizer_to_arrays, to_arrays)
from shaped_es.config import RunConfig
from shaped_es.envs.core import runs_serially
from shaped_es.rollout import EnvProbe, make_env, probe_env
from shaped_es.run_loop import RunLoop
from shaped_es.rundir.store import RunStore, StoreError


def _train_env(cfg: RunConfig):
    env = make_env(cfg.env, cfg.env_kwargs)
    if cfg.rollout.max_steps is not None:
        env = TimeLimit(env, cfg.rollout.max_steps)  # same episode cap as the ES rollouts
    return Monitor(env)


def env_time_limit(cfg: RunConfig) -> int | None:
    """The env's own episode limit, after checking its spaces fit the contract (``rollout.EnvProbe``)."""
    return probe_env(cfg.env, cfg.env_kwargs).time_limit


def build_model(cfg: RunConfig, s: PPOSettings) -> PPO:
    """A fresh SB3 PPO whose actor and critic are tanh MLPs with ``cfg.policy.hidden`` units."""
    vec = DummyVecEnv([lambda: _train_env(cfg)] * s.n_envs)
    hidden = list(cfg.policy.hidden)
    return PPO(
        "MlpPolicy", vec, learning_rate=s.learning_rate, n_steps=s.n_steps, batch_size=s.batch_size,
        n_epochs=s.n_epochs, gamma=s.gamma,
        gae_lambda=s.gae_lambda, clip_range=s.clip_range, ent_coef=s.ent_coef, vf_coef=s.vf_coef,
        max_grad_norm=s.max_grad_norm, target_kl=s.target_kl,
        policy_kwargs={"net_arch": {"pi": hidden, "vf": hidden}, "activation_fn": torch.nn.Tanh},
        seed=seeding.derive_seed(cfg.seed, seeding.STRATEGY), device="cpu", verbose=0,
    )


class _GenerationLog(BaseCallback):
    """Returns of the episodes finishing during a generation's rollouts, and the time spent collecting."""

    def __init__(self):
        super().__init__()
        self.returns: list[float] = []
        self.rollout_time_s = 0.0
        self._t0 = 0.0

    def _on_step(self) -> bool:
        for info in self.locals["infos"]:
            if "episode" in info:
                self.returns.append(float(info["episode"]["r"]))
        return True

    def _on_rollout_start(self) -> None:
        self._t0 = time.perf_counter()

    def _on_rollout_end(self) -> None:
        self.rollout_time_s += time.perf_counter() - self._t0


class PPORun(RunLoop):
    """The PPO generation loop (:class:`RunLoop` holds the lock, restores, writes rows and checkpoints,
    as for the ES trainer); a generation is ``iterations`` PPO iterations."""

    label = "ppo"

    def __init__(self, cfg: RunConfig, store: RunStore, settings: PPOSettings, progress: bool = True,
                 probe: EnvProbe | None = None, callback=None):
        super().__init__(cfg, store, "ppo", progress, callback)
        self.s = settings
        probe = probe or probe_env(cfg.env, cfg.env_kwargs)  # the env's time limit (``env_time_limit``)
        self.iterations = iterations_per_generation(cfg, settings, probe.time_limit)
        self.steps_per_generation = self.iterations * settings.n_steps * settings.n_envs
        self.model = build_model(cfg, settings)
        self.model.env.seed(seeding.derive_seed(cfg.seed, seeding.TRAIN, 0))
        self.best_state = copy_state(self.model.policy.state_dict())
        self.test = DeterministicEpisodes(cfg.env, cfg.env_kwargs, cfg.rollout.max_steps)

    # -- checkpointing -----------------------------------------------------------------------------
    def checkpoint_state(self) -> tuple[dict, dict]:
        policy = self.model.policy
        arrays = to_arrays(POLICY, policy.state_dict()) | to_arrays(BEST, self.best_state)
        opt_arrays, groups = optimizer_to_arrays(policy.optimizer)
        arrays |= opt_arrays
        arrays[RNG] = torch.get_rng_state().numpy().copy()
        meta = {"optim_param_groups": groups, "steps_per_generation": self.steps_per_generation,
                "iterations_per_generation": self.iterations, "ppo": asdict(self.s)}
        return arrays, meta

    def load_state(self, arrays: dict, meta: dict) -> None:
        policy = self.model.policy
        policy.load_state_dict(from_arrays(POLICY, arrays))
        self.best_state = from_arrays(BEST, arrays)
        optimizer_from_arrays(policy.optimizer, arrays, meta["optim_param_groups"])
        torch.set_rng_state(torch.from_numpy(np.array(arrays[RNG])))

    def resumed(self, arrays: dict, meta: dict) -> None:
        """The training envs restart from the root seed and the generation (their state is not saved)."""
        self.model.num_timesteps = self.c.env_steps
        self.model.env.seed(seeding.derive_seed(self.cfg.seed, seeding.TRAIN, self.c.generation))

    # -- one generation = ``iterations`` PPO iterations ---------------------------------------------
    def step(self, g: int) -> list[dict]:
        cfg, policy = self.cfg, self.model.policy
        t0, cpu0 = time.perf_counter(), time.process_time()
        before = actor_vector(policy)  # (n_actor,)
        log = _GenerationLog()
        self.model.learn(self.steps_per_generation, callback=log, reset_num_timesteps=False,
                         log_interval=None)
        train = np.asarray(log.returns or [ep["r"] for ep in self.model.ep_info_buffer] or [math.nan])
        row = {"generation": g, "env_steps": 0, "wall_time_s": 0.0, "cpu_time_s": 0.0,
               "train_reward_mean": float(train.mean()), "train_reward_max": float(train.max()),
               "train_reward_min": float(train.min()), "test_reward_mean": None, "test_reward_std": None,
               "test_reward_best_so_far": None, "test_env_steps": 0}
        E = cfg.rollout.test_episodes
        if E and (g % cfg.rollout.test_every == 0 or g == cfg.generations - 1):
            seeds = seeding.episode_seeds(cfg.seed, seeding.TEST, g, np.zeros(1), E)  # (1, E) as ES
            test_ret, test_steps = self.test.run(policy, seeds[0])
            if runs_serially(self.test.envs[0]):  # the test env took the simulator from the train env:
                self.model._last_obs = None  # SB3 resets it at the next learn() (a new training episode)
            row.update(test_reward_mean=float(test_ret.mean()), test_reward_std=float(test_ret.std()),
                       test_env_steps=test_steps)
            if test_ret.mean() > self.c.best_test_reward:
                self.c.best_test_reward = float(test_ret.mean())
                self.best_state = copy_state(policy.state_dict())
                self.best_generation = g + 1
        elif not E:
            self.best_state = copy_state(policy.state_dict())  # nothing to choose by: keep the latest
            self.best_generation = g + 1
        if math.isfinite(self.c.best_test_reward):
            row["test_reward_best_so_far"] = self.c.best_test_reward
        gen_time = time.perf_counter() - t0
        self.c.generation = g + 1
        self.c.env_steps += self.steps_per_generation
        self.c.cpu_time_s += time.process_time() - cpu0  # one process, one torch thread: PPO's CPU
        self.c.wall_time_s += gen_time
        row.update(env_steps=self.c.env_steps, gen_env_steps=self.steps_per_generation,
                   wall_time_s=self.c.wall_time_s, cpu_time_s=self.c.cpu_time_s, gen_time_s=gen_time,
                   rollout_time_s=log.rollout_time_s,
                   update_norm=float(np.linalg.norm(actor_vector(policy) - before)))
        return [row]

    def close(self) -> None:
        super().close()
        self.test.close()
        self.model.env.close()


def train_ppo(cfg: RunConfig, store: RunStore, progress: bool = True,
              settings: PPOSettings | None = None, probe: EnvProbe | None = None, callback=None) -> list[dict]:
    """Train (or resume) PPO into ``store`` on one torch thread; returns the metrics rows written
    (``callback``: see :mod:`shaped_es.monitor.callbacks`)."""
    threads = torch.get_num_threads()
    torch.set_num_threads(1)  # the paper's PPO: single core
    try:
        return PPORun(cfg, store, settings or ppo_settings(cfg), progress, probe, callback).run()
    finally:
        torch.set_num_threads(threads)


def load_policy(cfg: RunConfig, arrays: dict[str, np.ndarray], which: str = "best"):
    """The SB3 policy saved in a PPO checkpoint (``which``: 'best', or 'mean' for the latest weights)."""
    s = ppo_settings(cfg)
    model = build_model(cfg, s)
    prefix = BEST if which == "best" else POLICY
    try:
        model.policy.load_state_dict(from_arrays(prefix, arrays))
    except RuntimeError as exc:
        raise StoreError(f"PPO checkpoint does not fit the config's policy: {str(exc).splitlines()[0]}") from None
    model.policy.set_training_mode(False)
    model.env.close()
    return model.policy


def policy_fields(cfg: RunConfig, arrays: dict[str, np.ndarray], which: str, run_dir, obs_dim: int,
                  act_dim: int) -> dict:
    """``trained.load.Policy``'s fields of a PPO checkpoint (``methods.Method.policy_fields``)."""
    return {"sb3_policy": load_policy(cfg, arrays, which)}


def ppo_returns(cfg: RunConfig, arrays: dict[str, np.ndarray], which: str, seeds: np.ndarray, run_dir,
                executor: str, workers: int | None) -> np.ndarray:
    """Returns ``(E,)`` of the saved PPO policy on the episodes ``seeds`` ``(E,)``, in one process, as PPO
    trains (SB3's deterministic actions; ``methods.Method.evaluate``)."""
    from shaped_es.baselines.ppo_state import DeterministicEpisodes

    runner = DeterministicEpisodes(cfg.env, cfg.env_kwargs, cfg.rollout.max_steps)
    try:
        returns, _ = runner.run(load_policy(cfg, arrays, which), seeds)  # (E,)
    finally:
        runner.close()
    return returns
