"""What a Gymnasium env's ``reset`` and ``step`` hand a rollout, checked where it enters: each broken
rule of the contract is one :class:`BadOutput` naming the part (the rollout adds the env, seed and step)
and what a correct one looks like: the old Gym API (a 4-tuple from ``step``, ``reset`` returning the
observation only), a reward that is not one number, an observation that is not an array,
``info['position']`` / ``info['waypoint']`` missing, of another size than each other or non-finite."""

from __future__ import annotations

import numbers

import numpy as np

from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY

OLD_STEP = ("a 4-tuple from step (obs, reward, done, info: the old Gym API); Gymnasium's step returns "
            "(obs, reward, terminated, truncated, info)")
CONTRACT = (f"info['{POSITION_KEY}'] and info['{WAYPOINT_KEY}'], finite (d,) arrays of one d at reset and every "
            f"step (README: environment contract)")


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


def waypoint_pair(info: dict, d: int | None = None) -> tuple[np.ndarray, np.ndarray]:
    """``info['position']`` and ``info['waypoint']`` as float32 ``(d,)`` arrays, both present, of one
    size (``d``: the size they had at reset) and finite."""
    out = []
    for key in (POSITION_KEY, WAYPOINT_KEY):
        v = info.get(key)
        if v is None:
            raise BadOutput(f"no info['{key}'] (the contract: {CONTRACT})")
        try:
            a = np.asarray(v, dtype=np.float32).reshape(-1)
        except (TypeError, ValueError):
            raise BadOutput(f"an info['{key}'] that is not an array of numbers ({_shown(v)}); the contract: "
                            f"{CONTRACT}") from None
        if not np.isfinite(a).all():
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
