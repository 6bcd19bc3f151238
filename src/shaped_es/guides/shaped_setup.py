"""What the shaped method resolves before its first generation: the env's waypoint-space dimension (the
env contract, also checked by preflight), where its labels and cloning run (the size rule of
``shaped.py``'s docstring), and its settings dataclasses from the config sections."""

from __future__ import annotations

import dataclasses

import numpy as np

from shaped_es.config import ConfigError, RunConfig
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY
from shaped_es.policies import MLPSpec
from shaped_es.rollout import EnvProbe, probe_env

MASTER_MAX_PARAMS = 20_000_000  # P x n above which ``auto`` clones on the workers


def waypoint_dim(cfg: RunConfig, probe: EnvProbe | None = None) -> int:
    """Dimension of the env's waypoint space, from the reset info of ``probe`` (``probe_env(...,
    reset=True)``; probed here if None or not reset); one clear error if it lacks the contract."""
    if probe is None or (probe.reset_info is None and probe.reset_error is None):
        probe = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    if probe.reset_error is not None:
        raise probe.reset_error
    info = probe.reset_info
    if POSITION_KEY not in info or WAYPOINT_KEY not in info:
        raise ConfigError(f"--method shaped needs info['{POSITION_KEY}'] and info['{WAYPOINT_KEY}'] "
                          f"from {cfg.env} (see the README's environment contract)")
    return int(np.asarray(info[POSITION_KEY]).reshape(-1).shape[0])


def placement(cfg: RunConfig, spec: MLPSpec) -> str:
    """Where labels and cloning run: ``master`` or ``workers`` (the size rule of the module docstring)."""
    if cfg.shaping.placement != "auto":
        return cfg.shaping.placement
    population = 2 * cfg.es.pairs
    one_machine = cfg.executor in ("inline", "process")
    return "master" if one_machine and population * spec.num_params <= MASTER_MAX_PARAMS else "workers"


def from_section(cls, section, **resolved):
    """The shaping dataclass ``cls`` from its config ``section``: every field both have, then ``resolved``
    (the section's defaults are the dataclass's own, ``config.py``)."""
    names = [f.name for f in dataclasses.fields(cls) if f.name in type(section).model_fields]
    return cls(**{n: getattr(section, n) for n in names if n not in resolved}, **resolved)


def label_source(cfg: RunConfig, mphi, mphi_cfg, reference, where: str, probe: EnvProbe | None = None):
    """The run's label source (``shaping.labels``, ``shaping/labels.py``); one clear error when it cannot
    serve: ``reference`` without ``shaping.reference_run``, ``controller`` on an env without the hook
    (``where``: the resolved placement)."""
    from shaped_es.shaping.labels import ControllerLabels, MphiLabels, ReferenceLabels

    sh = cfg.shaping
    if sh.labels == "mphi":
        return MphiLabels(mphi, mphi_cfg.frame, mphi_cfg.query_scale)
    if sh.labels == "reference":
        if reference is None:
            raise ConfigError("shaping.labels=reference needs shaping.reference_run (a finished run of this "
                              "env whose best policy gives the labels)")
        if where == "workers" and sh.mechanism == "paper":
            raise ConfigError("shaping.labels=reference with mechanism 'paper' runs on the master "
                              "(shaping.placement=master)")
        return ReferenceLabels(reference)
    if probe is None or probe.controller is None:
        probe = probe_env(cfg.env, cfg.env_kwargs)
    if not probe.controller:
        raise ConfigError(f"shaping.labels=controller needs a scripted waypoint controller from {cfg.env} "
                          f"(env.unwrapped.waypoint_controller(obs, info); see the README's environment "
                          f"contract)")
    return ControllerLabels()
