"""Typed PPO hyperparameters and the env-step budget that makes a few PPO iterations one "generation".

Budget (the paper's Fig. 4 puts ES generations and PPO on the same axes): one ES generation evaluates
``2 * es.pairs`` members on ``rollout.episodes`` episodes each, so it uses at most
``2 * pairs * episodes * horizon`` env steps (every episode running to the horizon). One PPO
"generation" is the whole number of PPO iterations (rollouts of ``n_steps * n_envs`` env steps, each
followed by ``n_epochs`` of minibatch updates) nearest to that budget, at least one. So
``cfg.generations`` gives PPO about the largest budget the ES methods could have used, while PPO keeps
its usual rollout and minibatch sizes; ES episodes that end early use fewer steps, which is why every
run also logs ``env_steps``, CPU and wall time. ``steps_per_generation`` sets the budget directly.

The settings come from ``cfg.ppo`` (``config.PPOConfig``, Stable-Baselines3's PPO defaults with one env;
the actor and critic take ``cfg.policy.hidden`` with tanh, the same architecture as the ES policy).
:class:`PPOSettings` is that section as a frozen value: its defaults and rules are the section's.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, fields

from pydantic import ValidationError

from shaped_es.config import ConfigError, PPOConfig, RunConfig, first_error

_D = PPOConfig()  # the defaults (one truth: the config section)


@dataclass(frozen=True)
class PPOSettings:
    steps_per_generation: int | None = _D.steps_per_generation  # env-step budget per generation; None: ES's max
    n_steps: int = _D.n_steps  # env steps per env per PPO iteration (SB3 default)
    n_envs: int = _D.n_envs  # envs stepped in lock-step in this one process (the paper: single core)
    batch_size: int = _D.batch_size  # minibatch size (SB3 default)
    n_epochs: int = _D.n_epochs  # passes over each rollout
    learning_rate: float = _D.learning_rate  # Adam step size (constant)
    gamma: float = _D.gamma  # discount
    gae_lambda: float = _D.gae_lambda  # GAE lambda
    clip_range: float = _D.clip_range  # PPO ratio clip
    ent_coef: float = _D.ent_coef  # entropy bonus
    vf_coef: float = _D.vf_coef  # value loss weight
    max_grad_norm: float = _D.max_grad_norm  # gradient clipping
    target_kl: float | None = _D.target_kl  # early stop of an iteration's epochs (None: off)

    def __post_init__(self):
        try:  # the section's rules
            PPOConfig.model_validate(asdict(self))
        except ValidationError as exc:
            raise ConfigError(f"ppo.{first_error(exc)}") from None


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


def check_ppo(cfg: RunConfig, probe) -> None:
    """PPO's preflight check (``methods.Method.checks``): a PPO generation can be sized (e.g. the env has a
    time limit or ``rollout.max_steps`` is set)."""
    iterations_per_generation(cfg, ppo_settings(cfg), probe.time_limit)


def report_extra(cfg: RunConfig) -> dict:
    """What a benchmark report's summary.json adds for PPO runs: the settings they resolved to."""
    from dataclasses import asdict

    return {"ppo_settings": asdict(ppo_settings(cfg))}
