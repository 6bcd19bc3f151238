"""The one registry of training methods: what ``method:`` in a run config may name, and how each is built.

A method is a search strategy plus a guide (the per-generation hook that may shape its next ask) run by
the ES trainer, or a method with its own run loop (PPO). The run config's ``method`` field, the CLI's
``--method`` choices, the benchmark's method names and the trainer's builders all read :data:`METHODS`;
adding a method is its file (a strategy in ``strategies/``, a guide in ``guides/``, or its own run loop)
plus one entry here.

The parts are named by import path (``"module:attr"``, as Gymnasium's entry points) and imported on first
use (:func:`resolve`), so this table sits at the foot of the tree (the config reads it) while the parts
live in the layers above it. The ``*_args`` functions say which config fields each part reads.

Everything that differs per method is a field here (how it trains, what preflight checks, how its saved
policy is loaded and evaluated, the knobs named when its search diverges, what the report adds): no
module outside this one compares a method's name (``tests/test_methods.py`` checks).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any


def _no_args(*_) -> dict[str, Any]:
    return {}


def _shaped_guide_args(cfg, spec, store, probe, executor) -> dict[str, Any]:
    """The shaped guide's (``guides/shaped.py``), for every method that runs it."""
    return {"cfg": cfg, "spec": spec, "store": store, "probe": probe, "executor": executor}


@dataclass(frozen=True)
class Method:
    """How one method is built; see the module docstring."""

    # "module:attr" of ``train(cfg, store, progress=True, probe=None, callback=None) -> metrics rows``: trains
    # or resumes a run (``probe``: the run's ``rollout.EnvProbe`` if the caller made one, else it probes its
    # env; ``callback``: shaped_es.monitor.callbacks).
    train: str = "shaped_es.trainer:train"
    # ES methods: "module:attr" of the strategy class, built as ``cls(x0, **strategy_args(cfg, seed))``.
    strategy: str | None = None
    strategy_args: Callable[[Any, int], dict[str, Any]] = _no_args
    # ES methods: "module:attr" of the guide class, built as ``cls(**guide_args(cfg, spec, store, probe,
    # executor))`` (``probe``: the run's ``rollout.EnvProbe``; ``executor``: the run's, for start-up rollouts).
    guide: str = "shaped_es.guides:NoGuide"
    guide_args: Callable[[Any, Any, Any, Any, Any], dict[str, Any]] = _no_args
    # The guide reads the env's reset info: the run's one env probe also resets it (``EnvProbe.reset_info``).
    probe_reset: bool = False
    # The fields of the method-specific sections (``es``, ``shaping``, ``ppo``) it reads: "es.sigma" is a
    # field, "shaping" a whole section. The benchmark compares and reports runs by them.
    reads: tuple[str, ...] = ()
    about: str = ""  # what the method is, in a few words (the CLI's --method help)
    # Checks before a run writes anything (``preflight.check_run``, after the ones every method shares):
    # "module:attr" of ``check(cfg, probe) -> None``, raising ConfigError / EnvSpecError (one line).
    checks: tuple[str, ...] = ("shaped_es.preflight:check_es",)
    # ES methods: bytes of strategy state beyond the population, for ``n`` parameters (preflight's memory check).
    state_bytes: Callable[[Any, int], int] = lambda cfg, n: 4 * n * 8  # mean and optimizer state
    # "module:attr" of ``policy_fields(cfg, arrays, which, run_dir, obs_dim, act_dim) -> dict``: the
    # ``trained.load.Policy`` fields that make a saved policy act (ES: ``theta``, ``spec``; PPO: ``sb3_policy``).
    policy_fields: str = "shaped_es.trained.load:es_policy_fields"
    # "module:attr" of ``returns(cfg, arrays, which, seeds (E,), run_dir, executor, workers) -> (E,)``: the
    # saved policy's returns on the episodes ``seeds`` (``shaped-es evaluate``).
    evaluate: str = "shaped_es.trained.evaluate:es_returns"
    # The settings named when the search becomes non-finite ("lower es.sigma / es.lr").
    knobs: tuple[str, ...] = ("es.sigma", "es.lr")
    # "module:attr" of ``(cfg) -> dict`` merged into a report's summary.json (e.g. PPO's resolved settings).
    report_extra: str | None = None
    # ES methods: why ``es.obs_norm`` cannot be used with it yet (None: it can); preflight and the trainer
    # refuse the setting with this reason.
    # check-env's checks (cli/check_env.py) this method needs to pass: "waypoints", "time limit"
    needs: tuple[str, ...] = ()
    no_obs_norm: str | None = None
    # Its guide runs the compiled shaping kernels (shaping/kernels.py): a run says so in one line when they
    # are about to compile (shaping/kernel_notice.py).
    kernels: bool = False
    # The method whose steps a run of this one takes when its guide changes nothing (a shaped run that never
    # accepted a candidate: the same seed gives the same policies); the run says so at its end.
    base: str | None = None


def _es_args(cfg, seed: int) -> dict[str, Any]:
    """Vanilla-ES keywords (also Guided ES's, with ``alpha``)."""
    es = cfg.es
    return dict(sigma=es.sigma, lr=es.lr, pairs=es.pairs, seed=seed, fitness_shaping=es.fitness_shaping,
                optimizer=es.optimizer, momentum=es.momentum, weight_decay=es.weight_decay)


def _guided_args(cfg, seed: int) -> dict[str, Any]:
    return dict(alpha=cfg.es.alpha, **_es_args(cfg, seed))


def _cmaes_state_bytes(cfg, n: int) -> int:
    """Mean and paths, plus (below ``es.cmaes_diagonal_above``) the full covariance, its eigenbasis, a copy."""
    return 4 * n * 8 + (3 * n * n * 8 if n <= cfg.es.cmaes_diagonal_above else 0)


def _cmaes_args(cfg, seed: int) -> dict[str, Any]:
    es = cfg.es
    return dict(sigma=es.sigma, pairs=es.pairs, seed=seed, weight_decay=es.cmaes_weight_decay,
                mu=es.cmaes_mu, diagonal_above=es.cmaes_diagonal_above)


VANILLA_ES = "shaped_es.strategies.vanilla:VanillaES"
GUIDED_ES = "shaped_es.strategies.guided:GuidedES"
ES_READS = ("es.pairs", "es.sigma", "es.lr", "es.optimizer", "es.momentum", "es.weight_decay",
            "es.fitness_shaping", "es.obs_norm")  # what _es_args reads, and the trainer's es.obs_norm

METHODS: dict[str, Method] = {
    "vanilla": Method(strategy=VANILLA_ES, strategy_args=_es_args, reads=ES_READS,
                      about="antithetic ES with rank-shaped returns and Adam (Vanilla-ES)"),
    "guided": Method(strategy=GUIDED_ES, strategy_args=_guided_args, guide="shaped_es.guides:PastUpdateGuide",
                     guide_args=lambda cfg, spec, store, probe, executor: {"k": cfg.es.guided_k},
                     reads=ES_READS + ("es.alpha", "es.guided_k"),
                     about="Guided ES, the last ES updates as surrogate gradients (no waypoints)"),
    "cmaes": Method(strategy="shaped_es.strategies.cmaes:CMAES", strategy_args=_cmaes_args,
                    reads=("es.pairs", "es.sigma", "es.cmaes_mu", "es.cmaes_weight_decay",
                           "es.cmaes_diagonal_above", "es.obs_norm"), state_bytes=_cmaes_state_bytes,
                    about="CMA-ES (pycma; separable above a size)"),
    "shaped": Method(strategy=GUIDED_ES, strategy_args=_guided_args, guide="shaped_es.guides.shaped:ShapedGuide",
                     guide_args=_shaped_guide_args, base="vanilla",
                     probe_reset=True, reads=ES_READS + ("es.alpha", "shaping"),
                     checks=("shaped_es.preflight:check_es", "shaped_es.preflight:check_waypoints",
                             "shaped_es.guides.shaped_setup:check_shaped"),
                     knobs=("es.sigma", "es.lr", "shaping.eta"), needs=("waypoints",), kernels=True,
                     about="waypoint-shaped ES (the paper's method): action labels toward the env's waypoints "
                           "(M_phi, a learned inverse-dynamics model) train a clone of the mean, tried beside "
                           "the population as a candidate mean (shaping.mechanism; needs info['position'] "
                           "and info['waypoint'])"),
    "shaped_cmaes": Method(strategy="shaped_es.strategies.cmaes:CMAES", strategy_args=_cmaes_args,
                           guide="shaped_es.guides.shaped:ShapedGuide",
                           guide_args=_shaped_guide_args, base="cmaes",
                           probe_reset=True, state_bytes=_cmaes_state_bytes,
                           reads=("es.pairs", "es.sigma", "es.cmaes_mu", "es.cmaes_weight_decay",
                                  "es.cmaes_diagonal_above", "es.obs_norm", "shaping"),
                           checks=("shaped_es.guides.shaped_setup:check_shaped",
                                   "shaped_es.guides.shaped_setup:check_candidate_only"),
                           knobs=("es.sigma",), needs=("waypoints",), kernels=True,
                           about="the shaped method's candidate over CMA-ES (an accepted candidate becomes "
                                 "CMA's mean): for bodies where CMA-ES is the best baseline (arms)"),
    # its own run loop (Stable-Baselines3); es.pairs sets its env-step budget
    "ppo": Method(train="shaped_es.baselines.ppo:train_ppo", reads=("es.pairs", "ppo"), needs=("time limit",),
                  checks=("shaped_es.baselines.ppo_settings:check_ppo",),
                  policy_fields="shaped_es.baselines.ppo:policy_fields",
                  evaluate="shaped_es.baselines.ppo:ppo_returns",
                  report_extra="shaped_es.baselines.ppo_settings:report_extra",
                  about="PPO (Stable-Baselines3, one core), a generation = the env steps of one ES one"),
}


# How the shaped method's labels become search (``shaping.mechanism``): name -> "module:Class" of a
# ``guides.mechanisms.Mechanism`` (that package's docstring compares them); a new one is its file + one entry.
MECHANISMS: dict[str, str] = {
    "paper": "shaped_es.guides.mechanisms.paper:PaperSubspace",
    "candidate": "shaped_es.guides.mechanisms.candidate:MeanCandidate",
    "pair": "shaped_es.guides.mechanisms.pair:MeanPair",
}


def resolve(path: str) -> Any:
    """The object a ``"module:attr"`` path names (its module imported on first use)."""
    module, _, attr = path.partition(":")
    return getattr(importlib.import_module(module), attr)
