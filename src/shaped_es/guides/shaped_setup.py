"""What the shaped method resolves before its first generation: the env's waypoint-space dimension (the
env contract) and its label source (both also checked by preflight, before the run directory is
written), where its labels and cloning run (the size rule of ``shaped.py``'s docstring), and its settings
dataclasses from the config sections."""

from __future__ import annotations

import dataclasses

import numpy as np

from shaped_es.config import ConfigError, RunConfig
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY, contract_key_guess
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
    missing = [k for k in (POSITION_KEY, WAYPOINT_KEY) if k not in info]  # the one(s) missing, by name
    if missing:
        guess = contract_key_guess(missing, info)
        mean = f"; did you mean {' / '.join(map(repr, guess))}?" if guess else ""
        raise ConfigError(f"--method shaped needs info['{POSITION_KEY}'] and info['{WAYPOINT_KEY}'] "
                          f"from {cfg.env}; its reset info has no {' or '.join(repr(k) for k in missing)}{mean} "
                          f"(see the README's environment contract)")
    return int(np.asarray(info[POSITION_KEY]).reshape(-1).shape[0])


def placement(cfg: RunConfig, spec: MLPSpec) -> str:
    """Where labels and cloning run: ``master`` or ``workers`` (the size rule of the module docstring)."""
    if cfg.shaping.placement != "auto":
        return cfg.shaping.placement
    population = 2 * cfg.es.pairs
    one_machine = cfg.executor in ("inline", "process")
    return "master" if one_machine and population * spec.num_params <= MASTER_MAX_PARAMS else "workers"


def mphi_config(cfg: RunConfig, pos_dim: int):
    """M_phi's settings for this run: its config section, ``frame: auto`` resolved before any probe
    (``both`` for 2-D and larger waypoint spaces, ``world`` for 1-D), the seed derived from the root seed."""
    from shaped_es import seeding
    from shaped_es.shaping.settings import InverseDynamicsConfig

    mp = cfg.shaping.inverse_dynamics
    frame = mp.frame if mp.frame != "auto" else ("both" if pos_dim >= 2 else "world")
    return from_section(InverseDynamicsConfig, mp, frame=frame, seed=seeding.derive_seed(cfg.seed, seeding.SHAPING),
                        step_change=mp.step_change is True)  # auto: off until the label probe chooses


def from_section(cls, section, **resolved):
    """The shaping dataclass ``cls`` from its config ``section``: every field both have, then ``resolved``
    (the section's defaults are the dataclass's own, ``config/shaping.py``)."""
    names = [f.name for f in dataclasses.fields(cls) if f.name in type(section).model_fields]
    return cls(**{n: getattr(section, n) for n in names if n not in resolved}, **resolved)


def check_shaped(cfg: RunConfig, probe: EnvProbe) -> None:
    """The shaped method's preflight checks (``methods.Method.checks``): the env contract
    (``info['position']`` and ``info['waypoint']``), ``es.obs_norm`` only with mechanism ``candidate``, a
    label source that can serve, and a
    ``shaping.reference_run`` with a checkpoint of this env's observation size."""
    from shaped_es.guides.reference import reference_actions
    from shaped_es.rollout import policy_spec

    check_obs_norm(cfg)
    check_candidate_settings(cfg)
    spec = policy_spec(cfg, probe)
    check_period(cfg, waypoint_dim(cfg, probe))
    check_shoot_frame(cfg, waypoint_dim(cfg, probe))
    check_labels(cfg, spec, probe)
    if cfg.shaping.reference_run:
        reference_actions(cfg.shaping.reference_run, spec)


def check_shoot_frame(cfg: RunConfig, pos_dim: int) -> None:
    """The shooting labels' waypoint frame turns the first two waypoint coordinates: one ``ConfigError`` line on
    a 1-D waypoint space."""
    if cfg.shaping.inverse_dynamics.shoot_frame == "waypoint" and pos_dim < 2:
        raise ConfigError(f"shaping.inverse_dynamics.shoot_frame=waypoint needs a waypoint space of at least two "
                          f"coordinates (this env's has {pos_dim}); use world or auto")


def check_obs_norm(cfg: RunConfig) -> None:
    """``es.obs_norm`` works with mechanism ``candidate`` (the mean's clone is fitted on normalized states,
    ``mean_clone.py``); one ``ConfigError`` line for the others, which do not pass the normalizer yet."""
    if cfg.es.obs_norm and cfg.shaping.mechanism != "candidate":
        raise ConfigError(f"es.obs_norm is not supported with shaping.mechanism={cfg.shaping.mechanism} yet "
                          f"(only 'candidate' fits its clone through the policy's normalizer); set "
                          f"es.obs_norm=false or shaping.mechanism=candidate")


# settings only the candidate mechanism reads (the pair mechanism's clone reads steps, lr, batch_size,
# max_samples and record_every; paper's none of shaping.mean_clone)
CANDIDATE_ONLY = ("scales", "accept", "accept_margin", "warm_start", "extra_episodes", "keep_step",
                  "reset_momentum", "keep_step_repeat", "revert_margin", "revert_paired", "confirm")


def check_candidate_settings(cfg: RunConfig) -> None:
    """One ``ConfigError`` line when a setting only mechanism ``candidate`` reads was changed from its
    default while another mechanism runs (it would be ignored in silence)."""
    sh = cfg.shaping
    if sh.mechanism == "candidate":
        return
    default = type(sh.mean_clone)()
    changed = [f"shaping.mean_clone.{k}" for k in CANDIDATE_ONLY
               if getattr(sh.mean_clone, k) != getattr(default, k)]
    changed += [f"shaping.{k}" for k in ("backoff_after", "backoff_max", "backoff_judges_jumps",
                                         "backoff_keep_rate")
                if getattr(sh, k) != type(sh).model_fields[k].default]
    if changed:
        one = len(changed) == 1
        raise ConfigError(f"{', '.join(changed)} only appl{'ies' if one else 'y'} with shaping.mechanism=candidate "
                          f"(this run's is {sh.mechanism!r}, which ignores {'it' if one else 'them'}); drop "
                          f"{'it' if one else 'them'} or set shaping.mechanism=candidate")


def check_candidate_only(cfg: RunConfig, probe: EnvProbe) -> None:
    """``shaped_cmaes``: CMA-ES takes the candidate (``set_mean``), not a Guided-ES subspace or pair."""
    if cfg.shaping.mechanism != "candidate":
        raise ConfigError(f"--method shaped_cmaes uses shaping.mechanism=candidate (CMA-ES takes a candidate "
                          f"mean, not the {cfg.shaping.mechanism!r} mechanism's directions); drop the setting "
                          f"or use --method shaped")


def check_labels(cfg: RunConfig, spec: MLPSpec, probe: EnvProbe | None = None) -> None:
    """One clear ``ConfigError`` if ``shaping.labels`` cannot serve this run: ``reference`` without
    ``shaping.reference_run`` (or with mechanism ``paper`` on the workers), ``controller`` on an env without
    the hook. ``preflight.check_run`` calls it before the run directory is written (a fixed config can
    then be trained into the same ``--out``); :func:`label_source` again, as a guard."""
    sh = cfg.shaping
    if sh.labels == "reference":
        if not sh.reference_run:
            raise ConfigError("shaping.labels=reference needs shaping.reference_run (a finished run of this "
                              "env whose best policy gives the labels)")
        if sh.mechanism == "paper" and placement(cfg, spec) == "workers":
            raise ConfigError("shaping.labels=reference with mechanism 'paper' runs on the master "
                              "(shaping.placement=master)")
    elif sh.labels == "controller":
        if probe is None or probe.controller is None:
            probe = probe_env(cfg.env, cfg.env_kwargs)
        if not probe.controller:
            raise ConfigError(f"shaping.labels=controller needs a scripted waypoint controller from {cfg.env} "
                              f"(env.unwrapped.waypoint_controller(obs, info); see the README's environment "
                              f"contract)")


def label_source(cfg: RunConfig, spec: MLPSpec, mphi, mphi_cfg, reference, probe: EnvProbe | None = None):
    """The run's label source (``shaping.labels``, ``shaping/labels.py``), once :func:`check_labels` passes
    (``reference``: the reference run's policy, ``guides/reference.py``)."""
    from shaped_es.shaping.labels import ControllerLabels, MphiLabels, ReferenceLabels

    check_labels(cfg, spec, probe)
    if cfg.shaping.labels == "mphi":
        return MphiLabels(mphi, mphi_cfg.frame, mphi_cfg.query_scale, mphi_cfg.query_mix)
    if cfg.shaping.labels == "reference":
        return ReferenceLabels(reference)
    return ControllerLabels()


def check_period(cfg: RunConfig, pos_dim: int) -> None:
    """A ``position_period`` the env declares that the rollouts cannot use: one error line before the run
    directory is written (``rollout/periodic.py``); what it declares is kept for :func:`wrap_line`."""
    from shaped_es.rollout import periodic

    periodic.declaration(cfg.env, dict(cfg.env_kwargs), pos_dim)


WRAP_FILE = "position_period.json"  # RUN/: the period a shaped run takes its positions' steps modulo (none: no file)


def write_wrap_file(root, period, declared: bool, generation: int | None = None) -> None:
    """``RUN/position_period.json``: the period (one per coordinate, 0: none) and where it came from, so a
    finished run says it (the final JSON's ``shaping.position_period``; a new user's arm: 9/10 seeds with the
    wrap taken out, 0/10 without, and nothing in the folder said which); ``generation``: found in that
    generation's recorded rows (the rollouts after it took it the short way), not at the start."""
    import json
    from pathlib import Path

    from shaped_es.rundir.atomic import atomic_write_text

    d = {"position_period": [float(p) for p in period], "source": "declared" if declared else "detected"}
    if generation is not None:
        d["generation"] = int(generation)
    atomic_write_text(Path(root) / WRAP_FILE, json.dumps(d) + "\n")


def read_wrap_file(root) -> dict | None:
    """What :func:`write_wrap_file` wrote (None: no file, or not that file's JSON)."""
    import json
    from pathlib import Path

    try:
        d = json.loads((Path(root) / WRAP_FILE).read_text())
    except (OSError, ValueError):
        return None
    ok = isinstance(d, dict) and isinstance(d.get("position_period"), list) and d.get("source") in ("declared",
                                                                                                      "detected")
    return d if ok else None


def wrap_line(cfg: RunConfig, pos_dim: int) -> tuple[str, bool, np.ndarray | None]:
    """``(line, declared, period)``: the run's line where ``info['position']`` wraps (a heading in (-pi, pi];
    ``rollout/periodic.py``), what the recorded steps and the labels' queries do about it, ``""`` where it does not
    (or the env has a batched core: the rollouts there take the positions as the core reports them); whether the
    env declares its ``position_period`` (the guide's late check then calls the declaration wrong, not missing);
    and the period (None: nothing wraps)."""
    from shaped_es.rollout import periodic

    # no env made here where preflight's check_period read the declaration in this process (a train's start)
    declared = periodic.declaration(cfg.env, dict(cfg.env_kwargs), pos_dim).declares
    period = periodic.period_of(None, cfg.env, dict(cfg.env_kwargs), pos_dim)
    return periodic.wrap_text(period, declared), declared, period
