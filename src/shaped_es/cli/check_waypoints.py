"""check-env's waypoint check: whether the env keeps the waypoint contract ``--method shaped`` reads
(``info["position"]`` and ``info["waypoint"]``, equal ``(d,)`` shapes, finite, from ``reset`` and every ``step``)
in the recorded random-action episodes, and what the labels could not use there: a position that never moves, a
waypoint given relative to the body, a periodic position and a ``position_period`` that disagrees with the
episodes (:func:`_waypoints`). A broken contract is ``no``: only shaped reads it."""

from __future__ import annotations

import numpy as np

from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY, contract_key_guess
from shaped_es.rollout import EnvSpecError, periodic
from shaped_es.cli.check_result import NO, OK, WARN, Check


def _waypoints(runs: list[dict], env=None, env_id: str = "", env_kwargs: dict | None = None) -> Check:
    infos = [i for r in runs for i in r["infos"]]
    have = [POSITION_KEY in i and WAYPOINT_KEY in i for i in infos]
    # only shaped reads the two keys: a broken contract is "no" for it, never a FAIL for every method (a new
    # user's 3-d waypoint beside a 2-d position read "cannot train here" while --method vanilla trained)
    others = ": --method shaped cannot use it; every other method trains (README: environment contract)"
    if not any(have):
        return Check("waypoints", NO, f"{_missing_keys(infos)}: every method but shaped trains on it (README: "
                                      f"environment contract)")
    if not all(have):  # the first call without them, and which key (a new user's reset lacked them)
        where, missing = next(("reset" if t == 0 else f"step {t}", [k for k in (POSITION_KEY, WAYPOINT_KEY)
                                                                    if k not in i])
                              for r in runs for t, i in enumerate(r["infos"])
                              if POSITION_KEY not in i or WAYPOINT_KEY not in i)
        return Check("waypoints", NO, f"{' and '.join(f'info[{k!r}]' for k in missing)} missing from {where} "
                                      f"(the other calls have both; shaped needs them from reset and every step){others}")
    shapes = {(np.shape(i[POSITION_KEY]), np.shape(i[WAYPOINT_KEY])) for i in infos}
    # the rollouts read each flattened (env_probe.waypoint_pair): a (2, 1) column is the 2-d point it holds
    sizes = {(int(np.prod(p)), int(np.prod(w))) for p, w in shapes}
    if len(shapes) != 1 or len({n for pair in sizes for n in pair}) != 1 or next(iter(sizes))[0] == 0:
        got = "; ".join(f"position {p}, waypoint {w}" for p, w in sorted(shapes))
        return Check("waypoints", NO, f"position and waypoint must both be (d,) arrays of one d, got {got}{others}")
    if not all(np.isfinite(np.asarray(i[k], float)).all() for i in infos for k in (POSITION_KEY, WAYPOINT_KEY)):
        return Check("waypoints", NO, f"a position or waypoint is not finite{others}")
    d, shape = next(iter(sizes))[0], next(iter(shapes))[0]
    flat = "" if len(shape) == 1 else ", scalars read as (1,)" if not shape else f", {shape} arrays read flattened"
    try:
        wraps, odd = _wraps(env, env_id, env_kwargs, d)
    except EnvSpecError as exc:  # a position_period shaped cannot use (the other methods never read it)
        return Check("waypoints", NO, f"{exc}: --method shaped refuses it; every other method trains")
    moves = _motion(runs)
    return Check("waypoints", WARN if odd or moves else OK, f"info['{POSITION_KEY}'] and info['{WAYPOINT_KEY}'] "
                                                            f"({d}-d{flat}) from reset and every step: --method shaped "
                                                            f"can use it" + wraps + moves)


def _motion(runs: list[dict]) -> str:
    """``; but ...`` where the random-action episodes show a position the labels cannot use: one that never moves
    (a new user's env reported the reset's position every step), or a waypoint that moves by minus the position's
    step (given relative to the body, ``w - p``); ``""`` otherwise. Both trained worse than Vanilla-ES (a frozen
    position -75.7, a relative waypoint -61.0 against -58.4) while check-env said ok."""
    P = [np.stack([np.asarray(i[POSITION_KEY], np.float64).reshape(-1) for i in r["infos"]]) for r in runs
         if len(r["infos"]) > 1]  # per episode (T, d)
    W = [np.stack([np.asarray(i[WAYPOINT_KEY], np.float64).reshape(-1) for i in r["infos"]]) for r in runs
         if len(r["infos"]) > 1]
    if not P:
        return ""
    dp = np.concatenate([np.diff(p, axis=0) for p in P])  # (N, d) the position's steps
    dw = np.concatenate([np.diff(w, axis=0) for w in W])  # (N, d) the waypoint's
    step = np.linalg.norm(dp, axis=1)  # (N,)
    if not (step > 0).any():
        return (f"; but info['{POSITION_KEY}'] never moved in {len(dp)} random-action steps: the labels are actions "
                f"that move it (report the body's position each step, a copy, not the reset's array)")
    moving = step > 0
    opposite = np.linalg.norm(dw + dp, axis=1) <= 1e-6 * (1.0 + step)  # (N,) w moved by exactly -dp
    if opposite[moving].mean() > 0.9:
        return (f"; but info['{WAYPOINT_KEY}'] moved by minus the position's step on {opposite[moving].mean():.0%} "
                f"of the moving steps: is it relative to the body (w - p)? Give the waypoint where it is, in the "
                f"position's frame")
    return ""


def _missing_keys(infos: list[dict]) -> str:
    """``no info['waypoint'] (info['position'] is there; did you mean 'waypoints'?)``: which of the two keys no
    call gave, and the info's own keys that look like them (a new user's env said ``waypoints``)."""
    keys = {k for i in infos for k in i if isinstance(k, str)}
    missing = [k for k in (POSITION_KEY, WAYPOINT_KEY) if k not in keys]
    text = "no " + " / ".join(f"info[{k!r}]" for k in missing)
    there = [f"info[{k!r}] is there" for k in (POSITION_KEY, WAYPOINT_KEY) if k in keys]
    close = contract_key_guess(missing, keys)
    notes = there + ([f"did you mean {' / '.join(map(repr, close))}?"] if close else [])
    return text + (f" ({'; '.join(notes)})" if notes else "")


def _wraps(env, env_id: str, env_kwargs: dict | None, d: int) -> tuple[str, bool]:
    """``; info['position'] wraps ([0] at 2 pi; detected ...): shaped runs record it continuous ...``
    (``periodic.wrap_text``) where the position is periodic (a wrapped heading), ``""`` otherwise; and whether a
    declared ``position_period`` disagrees with what random-action episodes show (a new user's arm declared 360
    for radians, and None for joints that jump by 2 pi: both passed in silence)."""
    if env is None:
        return "", False
    period = periodic.period_of(env, env_id, dict(env_kwargs or {}), d)
    declared = periodic.is_declared(env)
    seen = periodic.detect_env(env_id, dict(env_kwargs or {})) if declared and periodic.detectable(env) else None
    mine = period if period is not None else np.zeros(d)
    odd = seen is not None and bool(np.any((seen > 0) & (seen != mine)))
    but = (f"; but random-action episodes jump by about a turn ({periodic.coords_text(seen)}): check "
           f"env.unwrapped.{periodic.PERIOD_ATTR}") if odd else ""
    if period is None:
        return but, odd
    return f"; {periodic.wrap_text(period, declared)}{but}", odd
