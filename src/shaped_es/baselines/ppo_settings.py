"""Typed PPO hyperparameters and the env-step budget that makes a few PPO iterations one "generation".

Budget (the paper's Fig. 4 puts ES generations and PPO on the same axes): one ES generation evaluates
``2 * es.pairs`` members on ``rollout.episodes`` episodes each, so it uses at most
``2 * pairs * episodes * horizon`` env steps (every episode running to the horizon). One PPO
"generation" is the whole number of PPO iterations (rollouts of ``n_steps * n_envs`` env steps, each
followed by ``n_epochs`` of minibatch updates) nearest to that budget, at least one. So
``cfg.generations`` gives PPO about the largest budget the ES methods could have used, while PPO keeps
its usual rollout and minibatch sizes; ES episodes that end early use fewer steps, which is why every
run also logs ``env_steps``, CPU and wall time. ``steps_per_generation`` sets the budget directly.

The settings come from ``cfg.ppo`` when the run config has that section, else from the defaults below
(Stable-Baselines3's PPO defaults with one env; the actor and critic take ``cfg.policy.hidden`` with tanh,
the same architecture as the ES policy).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from shaped_es.config import ConfigError, RunConfig


@dataclass(frozen=True)
class PPOSettings:
    steps_per_generation: int | None = None  # env-step budget per generation; None: ES's max per generation
    n_steps: int = 2048  # env steps per env per PPO iteration (SB3 default)
    n_envs: int = 1  # envs stepped in lock-step in this one process (the paper: single core)
    batch_size: int = 64  # minibatch size (SB3 default)
    n_epochs: int = 10  # passes over each rollout
    learning_rate: float = 3e-4  # Adam step size (constant)
    gamma: float = 0.99  # discount
    gae_lambda: float = 0.95  # GAE lambda
    clip_range: float = 0.2  # PPO ratio clip
    ent_coef: float = 0.0  # entropy bonus
    vf_coef: float = 0.5  # value loss weight
    max_grad_norm: float = 0.5  # gradient clipping
    target_kl: float | None = None  # early stop of an iteration's epochs (None: off)

    def __post_init__(self):
        positive = ("n_envs", "batch_size", "n_epochs", "learning_rate", "clip_range", "max_grad_norm")
        for name in positive:
            if not getattr(self, name) > 0:
                raise ConfigError(f"ppo.{name}: must be positive, got {getattr(self, name)}")
        if self.n_steps < 2:
            raise ConfigError(f"ppo.n_steps: must be at least 2, got {self.n_steps}")
        if self.steps_per_generation is not None and self.steps_per_generation <= 0:
            raise ConfigError(f"ppo.steps_per_generation: must be positive, got {self.steps_per_generation}")
        for name in ("gamma", "gae_lambda"):
            if not 0 <= getattr(self, name) <= 1:
                raise ConfigError(f"ppo.{name}: must lie in [0, 1], got {getattr(self, name)}")


def ppo_settings(cfg: RunConfig) -> PPOSettings:
    """Settings from ``cfg.ppo`` (a pydantic section, once the config has one) or the defaults."""
    section = getattr(cfg, "ppo", None)
    if section is None:
        return PPOSettings()
    data = section.model_dump() if hasattr(section, "model_dump") else dict(section)
    known = {f.name for f in fields(PPOSettings)}
    unknown = sorted(set(data) - known)
    if unknown:
        raise ConfigError(f"ppo: unknown settings {unknown}")
    return PPOSettings(**data)


def horizon(cfg: RunConfig, env_max_steps: int | None) -> int:
    """Episode length cap used for the budget: ``rollout.max_steps`` or the env's own time limit."""
    caps = [h for h in (cfg.rollout.max_steps, env_max_steps) if h]
    if not caps:
        raise ConfigError(f"ppo: env {cfg.env!r} has no time limit; set rollout.max_steps or "
                          "ppo.steps_per_generation")
    return min(caps)


def iterations_per_generation(cfg: RunConfig, s: PPOSettings, env_max_steps: int | None) -> int:
    """PPO iterations per generation: the whole number whose env steps come nearest the budget (>= 1)."""
    budget = s.steps_per_generation
    if budget is None:
        budget = 2 * cfg.es.pairs * cfg.rollout.episodes * horizon(cfg, env_max_steps)  # ES's max per gen
    return max(1, round(budget / (s.n_steps * s.n_envs)))
