"""Typed, validated run configuration (``config.yaml`` in every run directory).

A config file holds any subset of these fields; everything else takes the defaults below, and the run
directory stores the complete result, so ``shaped-es train --config RUN/config.yaml`` re-runs it.
Unknown keys and bad values are errors (one line each, naming the field; a misspelt key with the fields
it may mean, ``config/keys.py``, which also reads dotted keys).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import Field, ValidationError, model_validator

from shaped_es.config.keys import first_error, merge
# re-exported: reading a config's text (config/text.py) is where they live
from shaped_es.config.text import ConfigError, parse_set, parse_yaml, read_yaml, set_item  # noqa: F401
from shaped_es.executors import EXECUTORS
from shaped_es.methods import METHODS
# the shaping section and the scalar types live in their own files; re-exported here, the schema's one name
from shaped_es.config.shaping import CloningSettings, InverseDynamicsSettings, MeanCloneSettings, ShapingConfig  # noqa: F401
from shaped_es.config.scalars import SEED_LIMIT, Bool, ConfigWarning, Float, Int, _Strict  # noqa: F401


class PolicyConfig(_Strict):
    hidden: tuple[Int, ...] = Field((32, 32), description="hidden layer widths of the tanh MLP policy "
                                    "([]: a linear policy)")

    @model_validator(mode="after")
    def _positive(self):
        if any(h <= 0 for h in self.hidden):
            raise ValueError("hidden widths must be positive")
        return self


class ESConfig(_Strict):
    pairs: Int = Field(32, gt=0, description="antithetic pairs; population = 2 * pairs (paper: 64 members)")
    sigma: Float = Field(0.05, gt=0, le=1e4, description="search std; same meaning for vanilla and guided")
    lr: Float = Field(0.03, gt=0, le=1e4, description="step size gamma of the mean update (beta absorbed)")
    optimizer: Literal["adam", "sgd"] = Field("adam", description="optimizer applied to the ES gradient")
    momentum: Float = Field(0.0, ge=0, lt=1, description="SGD momentum (sgd only)")
    weight_decay: Float = Field(0.005, ge=0, description="L2 decay on the mean (vanilla, guided, shaped)")
    fitness_shaping: Literal["rank", "none"] = Field("rank", description="ranks in [-1, 1] (paper) or raw")
    alpha: Float = Field(0.9, ge=0, le=1, description="Guided-ES isotropic share (paper 0.6: 6/10 CarNav-v0 "
                         "seeds against 0.9's 9/10 with the paper's mechanism, docs/paper-construction.md)")
    guided_k: Int = Field(1, gt=0, description="'guided' method: past ES gradients kept as surrogates")
    cmaes_mu: Int = Field(25, gt=0, description="CMA-ES parents M_best (paper 25)")
    cmaes_weight_decay: Float = Field(0.05, ge=0, description="CMA-ES fitness weight decay (paper 0.05)")
    cmaes_diagonal_above: Int = Field(2000, gt=0, description="use separable CMA above this many params")
    obs_norm: Bool = Field(False, description="running observation normalization (ARS V2): policies see "
                           "clip((obs - mean) / sqrt(var + 1e-8), -5, 5), the statistics of the population's "
                           "training rollouts up to the previous generation; saved with the policy (vanilla, "
                           "guided, cmaes; PPO: its own; shaped: not yet)")


class RolloutConfig(_Strict):
    episodes: Int = Field(2, gt=0, description="training episodes per member, mean return (paper: 2)")
    test_episodes: Int = Field(15, ge=0, description="test episodes of the tested policy (paper: 15)")
    test_every: Int = Field(1, gt=0, description="evaluate the tested policy every N generations")
    test_policy: Literal["best", "mean"] = Field(
        "mean", description="ES methods' tested policy, one rule for all: best, the population member with the "
        "highest training return (paper); mean, the search's mean, the centre of the generation's population "
        "(what OpenAI-ES and ARS evaluate; pycma's xfavorite): on the same runs its late test reward is higher for "
        "20 of the suite's 27 (method, task) pairs and lower for 2, the swimmer's (docs/benchmarks/test_policy_v11)")
    max_steps: Int | None = Field(None, gt=0, description="cap on episode length (None: the env's limit; an env "
                                  "without one is cut at 10,000 steps, with a warning: rollout.DEFAULT_MAX_STEPS)")
    common_seeds: Bool = Field(True, description="all members of a generation share episode seeds")


class PPOConfig(_Strict):
    steps_per_generation: Int | None = Field(
        None, gt=0, description="PPO env steps per generation (None: 2*pairs*episodes*horizon, ES's max)")
    n_steps: Int = Field(2048, ge=2, description="env steps per env per PPO iteration (SB3 default)")
    n_envs: Int = Field(1, gt=0, description="envs stepped in lock-step in the one process")
    batch_size: Int = Field(64, gt=0, description="minibatch size")
    n_epochs: Int = Field(10, gt=0, description="passes over each rollout")
    learning_rate: Float = Field(3e-4, gt=0, description="Adam step size")
    gamma: Float = Field(0.99, ge=0, le=1, description="discount")
    gae_lambda: Float = Field(0.95, ge=0, le=1, description="GAE lambda")
    clip_range: Float = Field(0.2, gt=0, description="PPO ratio clip")
    ent_coef: Float = Field(0.0, ge=0, description="entropy bonus")
    vf_coef: Float = Field(0.5, ge=0, description="value-loss weight")
    max_grad_norm: Float = Field(0.5, gt=0, description="gradient clipping")
    target_kl: Float | None = Field(None, gt=0, description="early stop of an iteration's epochs")


class WandbConfig(_Strict):
    enabled: Bool = Field(False, description="log every metrics row to Weights & Biases under the TensorBoard "
                          "tags (pip install 'shaped-es[wandb]')")
    project: str = Field("shaped-es", description="W&B project")
    entity: str | None = Field(None, description="W&B entity (user or team; None: the account's default)")
    group: str | None = Field(None, description="W&B group (a benchmark sets its directory's name)")
    mode: Literal["online", "offline", "disabled"] | None = Field(
        None, description="offline: written under RUN/wandb/ for a later 'wandb sync', no network or account "
        "needed; None: W&B's own setting (WANDB_MODE, else online)")


class RunConfig(_Strict):
    env: str = Field("Pendulum-v1", description="Gymnasium id; 'module:Env-v0' imports module first")
    env_kwargs: dict[str, Any] = Field(default_factory=dict, description="keyword args for gym.make")
    method: Literal[tuple(METHODS)] = Field("vanilla", description="a name in methods.METHODS")
    generations: Int = Field(50, gt=0, description="generations to run (ES); PPO maps it to env steps")
    seed: Int = Field(0, ge=0, lt=SEED_LIMIT,
                      description="root seed (below 2**32); every member/episode seed derives from it")
    executor: Literal[tuple(EXECUTORS)] = Field("process", description="a name in executors.EXECUTORS")
    workers: Int | None = Field(None, gt=0, description="worker count (None: all cores)")
    address: str | None = Field(None, description="ray: 'auto' or HOST:PORT; None starts a local Ray")
    task_timeout_s: Float | None = Field(None, gt=0, description="a task running longer is retried")
    max_retries: Int = Field(3, ge=0, description="retries of tasks whose worker died or hung")
    eval_overlap: Bool = Field(
        True, description="run the best member's test episodes while the next generation rolls out "
        "(its metrics row is written once they finish); false: evaluate before moving on")
    eval_workers: Int = Field(
        0, ge=0, description="process executor: a separate pool of this many workers for test episodes "
        "(the paper's evaluation workers); 0 shares the training workers. ray/mpi schedule test "
        "episodes on the same cluster")
    clone_overlap: Bool = Field(
        False, description="shaped (candidate mechanism, master placement; inline/process executors, ES "
        "strategies whose ask is pure): the next generation's population rollouts start while the mean's "
        "clone runs on the master, its candidate's once the clone is ready (the same numbers); off by default: "
        "on an idle 2-core machine it made CarNav-v0's shaped generation 5-8% faster and UR5Reach-v0's "
        "15-20% slower (the candidate's and babblers' episodes become a second wave instead of riding in "
        "the population's lock-step loops); worth it with more cores than workers")
    checkpoint_every: Int = Field(1, gt=0, description="checkpoint every N generations")
    keep_checkpoints: Int = Field(3, gt=0, description="checkpoints kept on disk (newest)")
    tensorboard: Bool = Field(True, description="also write TensorBoard events")
    stop_at: Float | None = Field(None, description="end the run, as finished, once a test reward reaches "
                                  "this (None: run every generation)")
    video_every: Int | None = Field(None, gt=0, description="every N generations, render the best policy so far "
                                    "(one test episode, as shaped-es render) into RUN/videos/gen_NNNNNN.gif "
                                    "(None: no videos)")
    wandb: WandbConfig = Field(default_factory=WandbConfig)
    policy: PolicyConfig = Field(default_factory=PolicyConfig)
    es: ESConfig = Field(default_factory=ESConfig)
    rollout: RolloutConfig = Field(default_factory=RolloutConfig)
    shaping: ShapingConfig = Field(default_factory=ShapingConfig)
    ppo: PPOConfig = Field(default_factory=PPOConfig)


def build_config(data: dict[str, Any]) -> RunConfig:
    try:
        return RunConfig.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(f"invalid config: {first_error(exc, RunConfig)}") from None


def check_seed(seed, flag: str = "--seed") -> int:
    """A seed as ``train`` takes it (an integer in ``0 .. 2**32 - 1``), else one ``ConfigError`` line."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed < SEED_LIMIT:
        raise ConfigError(f"{flag} must be an integer from 0 to {SEED_LIMIT - 1} (seeds are 32-bit, as train's), "
                          f"got {seed}")
    return seed


def load_config(path: str | Path, overrides: dict[str, Any] | None = None) -> RunConfig:
    """Read a YAML config and apply ``overrides`` (dotted keys allowed: ``{"es.sigma": 0.1}``)."""
    data = read_yaml(path)
    return build_config(merge(data, overrides or {}))


def dump_config(cfg: RunConfig) -> str:
    return yaml.safe_dump(cfg.model_dump(mode="json"), sort_keys=False)
