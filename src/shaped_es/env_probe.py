"""An env before its first rollout: made with one clear error (``make_env``: unknown ids, a module that
raises or exits on import), its spaces checked against what the policy can use, its own time limit, and
a run config's MLP on it (``policy_spec``), from one env made, measured and closed (``probe_env``); and
what its ``reset`` and ``step`` hand a rollout, checked where it enters (``reset_output``, ``step_output``,
``reward``, ``observation``, ``waypoint_pair``): each broken rule of the contract is one
:class:`BadOutput` naming the part (the rollout adds the env, seed and step) and what a correct one looks
like -- the old Gym API (a 4-tuple from ``step``, ``reset`` returning the observation only), a reward
that is not one number, an observation that is not an array, ``info['position']`` / ``info['waypoint']``
missing, of another size than each other or non-finite. ``shaped_es.rollout`` re-exports these names."""

from __future__ import annotations

import difflib
import numbers
import traceback
import warnings
from dataclasses import dataclass, field

import gymnasium as gym
import numpy as np

from shaped_es.actions import flat_hint, is_choice, output_width
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY, get_batch_core, has_controller
from shaped_es.policies import MLPSpec


class EnvSpecError(ValueError):
    """The environment cannot be created or does not fit the policy/contract."""


class EnvError(EnvSpecError):
    """The environment failed while running: it raised, returned a non-finite reward or observation, or
    changed an observation's shape. The message is one line (the env's exception type and message);
    ``detail`` holds the full traceback (for a log file), from whichever process ran the env;
    ``worker_fault``: the env's exception marked its worker's resource as lost (a simulator server that
    stopped answering), which executors may retry elsewhere (``executors.base.is_worker_fault``)."""

    def __init__(self, message: str, detail: str = "", worker_fault: bool = False):
        super().__init__(message)
        self.detail = detail
        self.worker_fault = worker_fault

    def __reduce__(self):  # crosses process boundaries with its traceback text
        return type(self), (str(self), self.detail, self.worker_fault)


class EnvCloseWarning(UserWarning):
    """The env's ``close()`` raised: the work is done, so one warning line, not an error."""


def close_env(env, env_id: str | None = None) -> None:
    """``env.close()``; an exception from it is one warning line naming the env (close should release
    what the env holds without raising), not an internal error after the work was done."""
    try:
        env.close()
    except Exception as exc:  # noqa: BLE001 - the env's own close
        name = env_id or getattr(getattr(env, "spec", None), "id", None) or type(env).__name__
        warnings.warn(f"env {name!r} raised {exception_line(exc)} in close() (ignored; an env's close should "
                      f"release what it holds without raising)", EnvCloseWarning, stacklevel=2)


def exception_line(exc: BaseException) -> str:
    """``Type: first line of the message`` of an exception (one line)."""
    text = str(exc).strip().splitlines()
    return f"{type(exc).__name__}: {text[0]}" if text else type(exc).__name__


def make_env(env_id: str, env_kwargs: dict | None = None) -> gym.Env:
    """``gymnasium.make`` with one clear error for unknown ids (``module:Env-v0`` ids import the module), its
    observations flattened where they are not one vector (:func:`flat_observations`)."""
    try:
        return flat_observations(gym.make(env_id, **(env_kwargs or {})))
    except (gym.error.Error, ModuleNotFoundError) as exc:
        msg = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        if isinstance(exc, ModuleNotFoundError) and ":" in env_id:
            msg = _missing_module(env_id.split(":", 1)[0], exc) or msg
        elif ":" not in env_id and "doesn't exist" in msg and "Did you mean" not in msg:  # an own env, no module
            module, dot, name = env_id.rpartition(".")  # forcepoint.ForcePoint-v0: the module, then a dot
            example = f"{module}:{name}" if dot and module and name else f"mymodule:{env_id}"
            msg += (f" (an own env is named module:Id, e.g. --env {example}, and its module registers it: "
                    f"README, \"Your own env\")")
        elif ":" in env_id and not _registered_as(env_id.split(":", 1)[1]):  # no version of it either
            module, name = env_id.split(":", 1)
            near = difflib.get_close_matches(name, list(gym.registry), n=1, cutoff=0.8)  # a typo of an id it has
            if near:
                msg = f"its module {module!r} imports but registers no {name!r}; did you mean {module}:{near[0]}?"
            else:
                msg = (f"its module {module!r} imports but registers no {name!r}: call gymnasium.register"
                       f"({name!r}, entry_point=...) in it (README, \"Your own env\")")
        raise EnvSpecError(f"cannot make env {env_id!r}: {msg}") from None
    except Exception as exc:  # noqa: BLE001 - the env's module or constructor raised: one line + detail
        unexpected = [k for k in (env_kwargs or {}) if isinstance(exc, TypeError)
                      and f"unexpected keyword argument '{k}'" in str(exc)]
        if unexpected == ["preset"]:  # --preset on an env that has none
            from shaped_es.envs import BUILTIN

            raise EnvSpecError(f"env {env_id!r} has no presets: drop --preset (env_kwargs.preset); presets "
                               f"exist for {', '.join(BUILTIN)} (shaped-es envs lists them)") from None
        if unexpected:
            raise EnvSpecError(f"cannot make env {env_id!r}: it takes no keyword argument {unexpected[0]!r} "
                               f"(given in env_kwargs)") from None
        raise EnvError(f"cannot make env {env_id!r}: {exception_line(exc)}", traceback.format_exc()) from None
    except SystemExit as exc:  # a module that exits on import would end the command without a word
        raise EnvError(f"cannot make env {env_id!r}: importing or making it called sys.exit({exc.code!r})",
                       traceback.format_exc()) from None


def flat_observations(env: gym.Env) -> gym.Env:
    """``env``, or ``env`` under Gymnasium's ``FlattenObservation`` when its observation space is not a flat Box
    but Gymnasium can flatten it (a ``Dict`` such as a goal-conditioned env's ``observation`` /
    ``achieved_goal`` / ``desired_goal``, a ``Tuple``, an n-d ``Box``, a ``Discrete`` one-hot): the MLP reads
    one vector, in ``gymnasium.spaces.flatten``'s order (a ``Dict``'s keys sorted). Every env a run, ``evaluate``,
    ``render``, PPO and ``load_policy`` makes goes through here, so each sees the same vector; a space Gymnasium
    cannot flatten (``Sequence``, ``Graph``, ``Text``) is left for :func:`env_dims` to refuse."""
    space = env.observation_space
    if isinstance(space, gym.spaces.Box) and len(space.shape) == 1:
        return env
    try:
        if not space.is_np_flattenable:
            return env
    except (AttributeError, NotImplementedError):
        return env
    return gym.wrappers.FlattenObservation(env)


def flattened_from(env: gym.Env) -> gym.Space | None:
    """The env's own observation space where :func:`flat_observations` flattened it, else None."""
    return env.env.observation_space if isinstance(env, gym.wrappers.FlattenObservation) else None


def _registered_as(name: str) -> bool:
    """Some version of ``name`` (``MyEnv-v0``: ``MyEnv-v*``) is in Gymnasium's registry."""
    base = name.rsplit("-v", 1)[0]
    return any(k == name or k.rsplit("-v", 1)[0] == base for k in gym.registry)


def _missing_module(module: str, exc: ModuleNotFoundError) -> str | None:
    """Why ``module`` of a ``module:Env-v0`` id did not import: it is not on the path here (a run of an
    env defined next to it, used from another folder), or it imports a package that is not installed."""
    import os

    cause = exc.__cause__ if isinstance(exc.__cause__, ModuleNotFoundError) else exc
    missing = getattr(cause, "name", None)
    if missing is None:
        return None
    if missing == module or module.startswith(missing + "."):
        return (f"its module {module!r} cannot be imported from {os.getcwd()}: run from the folder that "
                f"holds {module.split('.')[0]}, or add that folder to PYTHONPATH")
    return f"its module {module!r} imports {missing!r}, which is not installed"


def env_dims(env: gym.Env) -> tuple[int, int]:
    """(obs_dim, act_dim) of a flat-Box-observation env (:func:`make_env` flattens the others Gymnasium can)
    with an action space a policy acts in (``actions.output_width``: a flat Box, Discrete, MultiDiscrete or
    MultiBinary; ``act_dim`` is the policy's output width)."""
    obs_space, act_space = env.observation_space, env.action_space
    if not isinstance(obs_space, gym.spaces.Box) or len(obs_space.shape) != 1:
        raise EnvSpecError(f"observation space must be a Box, or a space Gymnasium can flatten into one (Dict, "
                           f"Tuple, Discrete, MultiBinary, MultiDiscrete), got {obs_space}")
    width = output_width(act_space)
    if width is None:
        raise EnvSpecError(f"action space must be a flat Box, Discrete, MultiDiscrete or MultiBinary, got {act_space}"
                           f"{flat_hint(act_space)}")
    return int(obs_space.shape[0]), width


def env_time_limit(env: gym.Env) -> int | None:
    """The env's own episode limit: its ``spec.max_episode_steps`` (the built-in envs register a
    ``TimeLimit`` of their preset's horizon), else a ``TimeLimit`` among its wrappers, else the
    ``max_steps`` of its batched core, else None."""
    if env.spec is not None and env.spec.max_episode_steps:
        return int(env.spec.max_episode_steps)
    e = env
    while isinstance(e, gym.Wrapper):
        if isinstance(e, gym.wrappers.TimeLimit):
            return int(e._max_episode_steps)
        e = e.env
    core = get_batch_core(env)
    return int(core.max_steps) if core is not None else None


@dataclass(frozen=True)
class EnvProbe:
    """What a run needs of its env before the first rollout, from one env made, measured and closed."""

    obs_dim: int
    act_dim: int
    time_limit: int | None  # env_time_limit: the env's own episode limit (None: it has none)
    # Only when asked (``probe_env(..., reset=True)``: a method reading the env's info, ``methods.Method``):
    # the info of the same env's ``reset(seed=0)``, or the exception that reset raised, kept for the
    # caller to raise when its check comes (both None: not asked).
    reset_info: dict | None = field(default=None, compare=False, repr=False)
    reset_error: Exception | None = field(default=None, compare=False, repr=False)
    # the action space, when it is a Box with an infinite bound (the policy cannot scale to it)
    unbounded_action: str | None = None
    # Whether the env offers the optional scripted waypoint controller (envs/core.py hook)
    controller: bool | None = field(default=None, compare=False)
    # A space of choices (Discrete, MultiDiscrete, MultiBinary): "zero action" (a zero policy output) is then
    # its action 0, not a middle action
    discrete: bool = field(default=False, compare=False)
    # With ``reset``: whether a second ``reset(seed=0)`` gave another observation (the env ignores its seed)
    unseeded: bool = field(default=False, compare=False)


def probe_env(env_id: str, env_kwargs: dict | None = None, reset: bool = False) -> EnvProbe:
    """Make ``env_id`` once: its dims (after checking its spaces fit the contract) and its time limit;
    with ``reset``, also its reset info (one ``reset(seed=0)``, only for the methods that read it)."""
    env = make_env(env_id, env_kwargs)
    try:
        obs_dim, act_dim = env_dims(env)
        space = env.action_space
        unbounded = None
        if isinstance(space, gym.spaces.Box) and not (np.isfinite(space.low).all() and
                                                      np.isfinite(space.high).all()):
            unbounded = str(space)
        info, error, unseeded = None, None, False
        if reset:
            try:
                first, info = env.reset(seed=0)
                # a second reset with the same seed: an env that ignores it starts elsewhere (a new user's trained
                # and evaluated unreproducibly, and only check-env said so)
                unseeded = not _same_obs(first, env.reset(seed=0)[0])
            except Exception as exc:  # noqa: BLE001 - raised by whoever checks the reset info, as one line
                error = EnvError(f"env {env_id!r} raised {exception_line(exc)} in reset(seed=0)",
                                 traceback.format_exc())
        return EnvProbe(obs_dim, act_dim, env_time_limit(env), reset_info=info, reset_error=error,
                        unbounded_action=unbounded, controller=has_controller(env),
                        discrete=is_choice(space), unseeded=unseeded)
    finally:
        close_env(env, env_id)


def _same_obs(a, b) -> bool:
    """Two reset observations equal (one vector each: :func:`make_env` flattens every space a run takes); ones that
    are not arrays of numbers count as equal (``env_dims`` and the rollouts name those)."""
    try:
        return bool(np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True))
    except (TypeError, ValueError):
        return True


def probe_dims(env_id: str, env_kwargs: dict | None = None) -> tuple[int, int]:
    """(obs_dim, act_dim) of ``env_id`` (an env made, measured and closed)."""
    probe = probe_env(env_id, env_kwargs)
    return probe.obs_dim, probe.act_dim


def policy_spec(cfg, probe: EnvProbe | None = None) -> MLPSpec:
    """The MLP of a run config ``cfg`` (a ``config.RunConfig``) on its env: dims probed (or taken from
    ``probe``, the same env's), ``policy.hidden``."""
    probe = probe or probe_env(cfg.env, cfg.env_kwargs)
    if probe.unbounded_action is not None:  # low + (a + 1) / 2 * (high - low) would be inf - inf = NaN
        raise EnvSpecError(f"env {cfg.env!r} has an unbounded action space {probe.unbounded_action}: the "
                           f"policy's tanh output in [-1, 1] is scaled to the box's bounds, so they must be "
                           f"finite; give the env's action space the bounds its actions live in (Gymnasium's "
                           f"ClipAction wrapper makes them infinite: leave it out, the policy's actions are "
                           f"already within the bounds)")
    return MLPSpec(probe.obs_dim, probe.act_dim, tuple(cfg.policy.hidden))


# -- what reset and step return, against the contract ---------------------------------------------------
OLD_STEP = ("a 4-tuple from step (obs, reward, done, info: the old Gym API); Gymnasium's step returns "
            "(obs, reward, terminated, truncated, info)")
CONTRACT = (f"info['{POSITION_KEY}'] and info['{WAYPOINT_KEY}'], finite (d,) arrays of one d at reset and every "
            f"step, the last waypoint (the goal) kept once it is reached (README: environment contract)")


class BadOutput(ValueError):
    """What the env returned breaks the contract (message: what it returned and what is wanted)."""


def _a(x) -> str:
    """``a list`` / ``an array of shape (3,)``: what ``x`` is, with its article."""
    if isinstance(x, np.ndarray):
        return f"an array of shape {x.shape}"
    name = type(x).__name__
    return f"{'an' if name[0] in 'aeiou' else 'a'} {name}"


def _shown(x) -> str:
    text = repr(x)
    return text if len(text) <= 40 else text[:37] + "..."


def reset_output(out) -> tuple:
    """``(obs, info)`` of a ``reset`` result."""
    if not (isinstance(out, tuple) and len(out) == 2 and isinstance(out[1], dict)):
        what = f"a {len(out)}-tuple" if isinstance(out, tuple) else _a(out)
        raise BadOutput(f"{what} from reset instead of (observation, info) (the old Gym API returned the "
                        f"observation only); Gymnasium's reset returns (obs, info)")
    return out


def step_output(out) -> tuple:
    """``(obs, reward, terminated, truncated, info)`` of a ``step`` result."""
    if isinstance(out, tuple) and len(out) == 4:
        raise BadOutput(OLD_STEP)
    if not (isinstance(out, tuple) and len(out) == 5 and isinstance(out[4], dict)):
        what = f"a {len(out)}-tuple" if isinstance(out, tuple) else _a(out)
        raise BadOutput(f"{what} from step; Gymnasium's step returns (obs, reward, terminated, truncated, "
                        f"info: a dict)")
    return out


def old_api(exc: BaseException) -> bool:
    """Gymnasium's own wrappers unpacking an old-API 4-tuple from the env's ``step``."""
    return isinstance(exc, ValueError) and "expected 5, got 4" in str(exc)


def reward(r) -> float:
    """One number (a Python or NumPy real, or an array of one), as a float; a string is not one."""
    if isinstance(r, numbers.Real):
        return float(r)
    if isinstance(r, np.ndarray) and r.size == 1 and r.dtype.kind in "biuf":
        return float(r.reshape(()))
    what = f"an array of shape {r.shape}" if isinstance(r, np.ndarray) else \
        f"{_a(r)} ({_shown(r)})"
    raise BadOutput(f"a reward that is {what}; step's reward must be one number (a float)")


def observation(o, shape: tuple) -> np.ndarray:
    """The observation as float32, of the observation space's ``shape``."""
    try:
        a = None if isinstance(o, (dict, str, bytes)) else np.asarray(o, dtype=np.float32)
    except (TypeError, ValueError):
        a = None
    if a is None:
        raise BadOutput(f"an observation that is {_a(o)}, not an array of shape {shape} "
                        f"(its observation space)")
    return a


def waypoint_pair(info: dict, d: int | None = None, finite: bool = True,
                  dtype=np.float32) -> tuple[np.ndarray, np.ndarray]:
    """``info['position']`` and ``info['waypoint']`` as ``(d,)`` arrays of ``dtype``, both present, of one
    size (``d``: the size they had at reset) and finite (``finite=False``: not checked here; a rollout checks
    every env's pair at once each step and calls this again on the one that is not, for its message)."""
    p, w = info.get(POSITION_KEY), info.get(WAYPOINT_KEY)
    if not finite and type(p) is np.ndarray and type(w) is np.ndarray and p.dtype.kind == "f" \
            and w.dtype.kind == "f" and p.size == w.size and p.size and (d is None or p.size == d):
        # the common case, a step of a recorded rollout: float arrays (~1 us against ~10 for the checks below)
        return p.astype(dtype).reshape(-1), w.astype(dtype).reshape(-1)
    out = []
    for key in (POSITION_KEY, WAYPOINT_KEY):
        v = info.get(key)
        if v is None:
            raise BadOutput(f"no info['{key}'] (the contract: {CONTRACT})")
        try:
            a = np.asarray(v, dtype=dtype).reshape(-1)
        except (TypeError, ValueError):
            raise BadOutput(f"an info['{key}'] that is not an array of numbers ({_shown(v)}); the contract: "
                            f"{CONTRACT}") from None
        if finite and not np.isfinite(a).all():
            raise BadOutput(f"a non-finite info['{key}'] ({_shown(a.tolist())})")
        out.append(a)
    pos, wp = out
    if pos.shape != wp.shape or pos.size == 0:
        raise BadOutput(f"info['{WAYPOINT_KEY}'] of size {wp.size} and info['{POSITION_KEY}'] of size {pos.size} "
                        f"(the contract: {CONTRACT})")
    if d is not None and pos.size != d:
        raise BadOutput(f"info['{POSITION_KEY}'] of size {pos.size} after size {d} at reset (the contract: "
                        f"{CONTRACT})")
    return pos, wp
