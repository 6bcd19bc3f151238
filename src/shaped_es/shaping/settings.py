"""The shaping layer's typed settings: ``M_phi``'s (:class:`InverseDynamicsConfig`) and cloning's
(:class:`CloningConfig`).

These dataclasses are the one source of their defaults: the run config's ``shaping.inverse_dynamics``
and ``shaping.cloning`` sections (``config/shaping.py``) read their defaults from here, and
``guides/shaped.py`` builds these from a run's sections (``frame: auto`` resolved there, the seed
derived from the root seed). This module imports neither torch nor ``config`` (the layers: shaping
lies below config).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from shaped_es.shaping.frames import FRAMES

TARGETS = ("one_step", "hindsight", "matched", "chunk")
LABEL_SOURCES = ("mphi", "reference", "controller")  # shaping/labels.py
ACCEPT_RULES = ("best", "mean", "paired", "best_paired")
SHOOT_MODELS = ("chunk", "rollout")  # the shooting labels' forward model (forward_shoot.py, forward_rollout.py)
SHOOT_FRAMES = ("auto", "world", "waypoint")  # the shooting labels' frame (forward_shoot.py; auto: the probe's)
SHOOT_COSTS = ("min", "mean")  # how the shooting labels score a held action's path (shaping/forward_shoot.py)
FILTERS = ("total", "positive", "none")
QUERY_SCALES = ("raw", "own_step")


@dataclass(frozen=True)
class InverseDynamicsConfig:
    hidden: tuple[int, ...] = (20, 20)  # ReLU hidden widths; paper: (20, 20) nav, (20, 20, 20) arm
    lr: float = 1e-3  # Adam learning rate (paper)
    batch_size: int = 64  # minibatch size (paper); rows drawn uniformly with replacement
    steps_per_generation: int = 500  # default number of train() iterations per generation
    min_return: float = 5.0  # episodes whose cumulative reward is below this are not used (paper)
    max_dataset: int = 100_000  # cap on aggregated transitions; the oldest are dropped first (FIFO)
    clip_input: float = 10.0  # standardized inputs are clipped to [-clip, clip] (far waypoints)
    frame: str = "world"  # displacement frame: "world" (paper) or "motion" (agent's heading; frames.py)
    targets: str = "one_step"  # training displacements: one_step (paper) | hindsight | matched | chunk
    horizon: int = 8  # hindsight/matched: at most this many steps ahead; chunk: its length
    filter: str = "none"  # which return min_return tests: none (keep all) | positive (paper) | total
    query_scale: str = "raw"  # label queries: raw w_t - p_t (paper) | own_step (query_displacement)
    query_mix: float = 1.0  # label queries: (1 - mix) (p_t - p_{t-1}) + mix (w_t - p_t) (mixed_query; 1: paper)
    step_change: bool = False  # also input the displacement's change from the last step (world, both frames)
    seed: int = 0  # seeds weight init and minibatch sampling

    def __post_init__(self):
        if not self.hidden or min(self.hidden) <= 0:
            raise ValueError(f"hidden widths must be positive, got {self.hidden}")
        if self.lr <= 0 or self.batch_size <= 0 or self.max_dataset <= 0 or self.clip_input <= 0:
            raise ValueError("lr, batch_size, max_dataset and clip_input must be positive")
        if self.frame not in FRAMES:
            raise ValueError(f"frame must be one of {FRAMES}, got {self.frame!r}")
        if not 0.0 < self.query_mix <= 1.0:
            raise ValueError(f"query_mix must be in (0, 1], got {self.query_mix}")
        if self.query_scale not in QUERY_SCALES:
            raise ValueError(f"query_scale must be one of {QUERY_SCALES}, got {self.query_scale!r}")
        if self.targets not in TARGETS or self.filter not in FILTERS or self.horizon < 1:
            raise ValueError(f"targets must be one of {TARGETS}, filter one of {FILTERS}, horizon >= 1; got "
                             f"{self.targets!r}, {self.filter!r}, {self.horizon}")


@dataclass(frozen=True)
class CloningConfig:
    steps: int = 20  # gradient steps per member per generation (0: theta* = theta)
    lr: float = 1e-3  # optimizer step size
    batch_size: int = 64  # samples per member per step, drawn with replacement; <= 0: full data every step
    optimizer: Literal["adam", "sgd"] = "adam"  # Adam (fresh state per call) or plain SGD
    max_samples: int = 4000  # only the most recent samples of each D_i are used; <= 0: all
    seed: int = 0  # per-member seeds default to SeedSequence([seed, row]) when none are given
    noise: float = 0.0  # > 0: each step's gradient at theta + noise * z (shaping/param_noise.py; the mean's
    #                     clone: mean_clone.noise * es.sigma); minibatch fits only (batch_size > 0)

    def __post_init__(self):
        if self.steps < 0 or self.lr <= 0 or self.optimizer not in ("adam", "sgd") or not self.noise >= 0 \
                or (self.noise > 0 and self.batch_size <= 0):
            raise ValueError(f"bad cloning config: steps={self.steps} lr={self.lr} "
                             f"optimizer={self.optimizer!r} noise={self.noise} (noise needs batch_size > 0)")


@dataclass(frozen=True)
class MeanCloneConfig:
    """The ``candidate`` and ``pair`` mechanisms' clone of the mean (``guides/mechanisms/``)."""

    steps: int = 200  # Adam steps of the mean's clone per generation (fresh optimizer state each time)
    lr: float = 3e-3  # its step size
    batch_size: int = 256  # rows per step, drawn with replacement from the recent recorded steps
    max_samples: int = 0  # only the newest rows of the last ``history`` generations (<= 0: all of them)
    record_every: int = 1  # the rollouts keep the steps of every k-th member (and of every candidate)
    noise: float = 1.0  # > 0: each Adam step's gradient is taken at theta + noise * es.sigma * z (the search's own
    #                     parameter noise; shaping/param_noise.py), from generation noise_from on: a plain clone can sit
    #                     where the return is sharp, and the ES steps around it lose ground (docs/benchmarks/noise_from_v29)
    noise_from: int = 15  # the noise applies to the clones made from this generation on (0-based, as metrics.csv
    #                       counts); before it a plain fit: the early jumps, whose size gives the speed (noise from
    #                       generation 0 took 1.3-1.9x the generations on CarNav-v0 and UR5Reach-v0: clone_noise_v28)
    noise_ramp: int = 0  # > 0: the noise grows linearly over this many generations from noise_from (the g-th
    #                     noisy clone, 1-based, gets min(1, g / noise_ramp) of it); 0: all of it at once
    scales: tuple[float, ...] = (1.0,)  # candidate: mu + s (theta* - mu) for each s, evaluated
    accept: str = "paired"  # candidate: the best one becomes the mean if it beats every member ("best"),
    #   the mean's own return on the same episodes ("mean"), the mean by more than a standard error of
    #   the paired differences over every episode both ran ("paired"), or both of best and paired
    accept_margin: float = 1.0  # paired / best_paired: the candidate's mean paired difference must exceed this
    #                             many standard errors of it
    accept_fresh: bool = False  # paired: the test runs on the extra episodes only (the pick of the best candidate saw
    #                              the common ones: winner's curse)
    pick_all: bool = False  # candidate: the candidate tested is the one with the best mean return over every episode
    #                         the candidates ran (the common and extra ones), not over the common ones alone
    accept_flat: bool = True  # candidate: where every member returned the same (no signal for the ES step), a candidate
    #                            whose mean paired gain is positive wins (a sparse reward's one success never passes
    #                            paired: x / n is exactly its own standard error)
    warm_start: bool = True  # the clone starts from the previous generation's clone (a DAgger learner
    #                           kept across generations) instead of the mean
    extra_episodes: int = 4  # candidate: the candidates and the mean also run this many more episodes,
    #                          on which a winner must beat the mean too
    keep_step: bool = True  # candidate: an accepted candidate also takes the ES update it replaces
    #                           (mu_{g+1} = c_g + (mu_{g+1} - mu_g)) instead of discarding it
    reset_momentum: bool = False  # candidate: an accepted jump also resets the ES optimizer's momentum
    keep_step_repeat: bool = False  # keep_step also when the previous generation's mean was a jump too
    #                                 (False, the suite's choice: a second jump in a row lands on the candidate)
    revert_margin: float = 0.0  # candidate: > 0: a jump is undone when the next population (sampled around it)
    #                             has a mean return below the population's before the jump by more than this
    #                             many standard errors of the difference (0: jumps are never undone)
    revert_paired: float = 3.0  # candidate: > 0: after a jump, the mean the ES step alone gave (what the jump replaced)
    #                               runs beside the next generation, and the jump is undone if it beats the jumped mean
    #                               by more than this many standard errors of the paired differences: a candidate is
    #                               judged against mu_g but replaces mu_{g+1}, which a productive ES step has already
    #                               moved past it (0: no such row; 3 against 2: the same on the suite but UR5Reach-v0,
    #                               docs/benchmarks/revert_paired_v22)
    check_episodes: int = 0  # candidate: a winner and the mean run this many more episodes at once (a second wave,
    #                          on winning generations only) and the jump needs the paired test again on every
    #                          episode the winner was not picked on (extra + these): the pick of the best of
    #                          several candidates on two episodes is a winner's curse (0: no check)
    confirm: bool = False  # candidate: a winner is evaluated again beside the next generation and
    #                        becomes the mean only if it beats the mean's return there
    probe_candidate: bool = True  # candidate: the label probe's best simulated candidate is judged at generation 0
    #                               (guides/probe_candidate.py); a loss there does not count against the labels

    def __post_init__(self):
        if self.steps < 0 or self.lr <= 0 or self.batch_size <= 0 or self.record_every < 1 or not self.noise >= 0 \
                or self.noise_from < 0 or self.noise_ramp < 0 \
                or self.extra_episodes < 0 or self.check_episodes < 0 or not self.accept_margin >= 0 or not self.revert_margin >= 0 \
                or not self.revert_paired >= 0:
            raise ValueError(f"bad mean-clone config: steps={self.steps} lr={self.lr} "
                             f"batch_size={self.batch_size} record_every={self.record_every} noise={self.noise} "
                             f"noise_from={self.noise_from} noise_ramp={self.noise_ramp} "
                             f"accept_margin={self.accept_margin} revert_margin={self.revert_margin} "
                             f"revert_paired={self.revert_paired}")
        if not self.scales or any(not s > 0 for s in self.scales) or self.accept not in ACCEPT_RULES:
            raise ValueError(f"mean-clone scales must be positive and accept one of {ACCEPT_RULES}, got "
                             f"{self.scales!r}, {self.accept!r}")
