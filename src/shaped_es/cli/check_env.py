"""What an env needs to train here, checked by running it (``shaped-es check-env ID``; the habit of
Stable-Baselines3's ``check_env``).

:func:`check_env` makes the env and runs a few episodes of random actions, reporting one :class:`Check` per
requirement: Gymnasium's own API checker (a warning at most: training needs only what the checks below test), the
spaces the policy needs (a flat ``Box`` observation, or a space Gymnasium flattens into one, a ``Dict`` say; a
flat ``Box`` action with finite bounds, which the policy's ``[-1, 1]`` output is rescaled to, or a space of
choices: ``Discrete``, ``MultiDiscrete``, ``MultiBinary``), seeding (the same ``reset(seed=s)`` and actions give
the same episode: runs reproduce and the members of a generation face the same episodes), finiteness and fixed
shapes of observations and rewards (a run stops at the first that is not), a time limit (PPO's budget needs one;
without it an episode that never ends never returns), the success threshold ``benchmark`` uses (optional), and the
waypoint contract of ``--method shaped`` (``info["position"]`` and ``info["waypoint"]``, equal ``(d,)`` shapes,
finite, from ``reset`` and every ``step``). A check's ``status`` is ``ok``, ``no`` (an optional capability the env
lacks: only ``shaped`` needs waypoints), ``warn`` (it trains, with a caveat) or ``FAIL`` (it cannot train). A
broken waypoint contract is ``no``: only shaped reads it.

``describe_env.py`` holds the short form ``shaped-es envs`` lists for every registered id.
"""

from __future__ import annotations

import re
import time
import warnings
from dataclasses import asdict, dataclass

import gymnasium as gym
import numpy as np

from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY, contract_key_guess, get_batch_core, has_controller
from shaped_es.actions import action_problem, action_text, flat_hint, is_choice, output_width, zero_action
from shaped_es.env_probe import BadOutput
from shaped_es.env_probe import reward as one_reward
from shaped_es.rollout import EnvSpecError, close_env, flattened_from, make_env, periodic

OK, NO, WARN, FAIL = "ok", "no", "warn", "FAIL"
_ANSI = re.compile(r"\x1b\[[0-9;]*m")


@dataclass(frozen=True)
class Check:
    name: str  # what is checked, e.g. "spaces"
    status: str  # OK / NO / WARN / FAIL
    detail: str  # one line


def trains_with(checks: list[Check]) -> list[str]:
    """The methods the env trains with, given its checks (none if one failed)."""
    from shaped_es.methods import METHODS

    by = {c.name: c.status for c in checks}
    if FAIL in by.values():
        return []
    return [m for m, method in METHODS.items() if all(by.get(need) == OK for need in method.needs)]


def check_env(env_id: str, env_kwargs: dict | None = None, episodes: int = 2, max_steps: int = 200,
              seed: int = 0) -> list[Check]:
    """The checks of the module docstring on ``episodes`` episodes of at most ``max_steps`` random steps
    each (``EnvSpecError`` if the env cannot be made at all)."""
    import shaped_es  # noqa: F401 - registers the built-in envs

    env = make_env(env_id, env_kwargs)
    try:
        checks = [*_gym_api(env_id, env_kwargs), _spaces(env)]
        if checks[-1].status == FAIL:
            return checks
        shown = {c.detail for c in checks if c.name == "gymnasium API"}
        with warnings.catch_warnings(record=True) as again:  # the same checker's warnings, from the episodes below
            warnings.simplefilter("always")
            checks += [_time_limit(env), _threshold(env_id, env_kwargs)]
            checks += _episodes(env, env_id, env_kwargs, episodes, max_steps, seed)
            checks.append(_controller(env, max_steps))
        for w in dict((_line(str(w.message)), w) for w in again).values():
            # a warning the gymnasium API line already shows is not counted again (a new user's reward array was a
            # line, then "1 warning from gymnasium"); the others go on as they came
            if _line(str(w.message)).removeprefix("WARN: ") not in shown:
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        return checks
    finally:
        close_env(env)


# Gymnasium's checker's advice that does not apply here: infinite observation bounds (its own MuJoCo envs have
# them; the policy takes raw observations, es.obs_norm learns their scale) and a non-normalized action Box (the
# policy's [-1, 1] output is rescaled to the Box's bounds; the spaces line says so)
_NOT_APPLICABLE = re.compile(r"observation space (minimum|maximum) value is -?infinity|symmetric and normalized space")
API_LINES = 4  # the checker's warnings shown a line each (a new user's env had two; the rest are counted)


def _gym_api(env_id: str, env_kwargs: dict | None) -> list[Check]:
    """Gymnasium's ``env_checker.check_env`` on a fresh env (it steps and reseeds the env it gets): one line
    per distinct warning (at most :data:`API_LINES`)."""
    from gymnasium.utils.env_checker import check_env as gym_check

    env = make_env(env_id, env_kwargs)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                gym_check(env.unwrapped, skip_render_check=True, skip_close_check=True)
            except Exception as exc:  # noqa: BLE001 - its verdict (what training needs is checked below)
                return [Check("gymnasium API", WARN, _line(f"its checker fails: {type(exc).__name__}: {exc}"))]
    finally:
        close_env(env)
    notes = [n for n in dict.fromkeys(_line(str(w.message)).removeprefix("WARN: ") for w in caught)
             if not _NOT_APPLICABLE.search(n)]
    if not notes:
        return [Check("gymnasium API", OK, "gymnasium.utils.env_checker.check_env passes")]
    shown = notes[:API_LINES]
    if len(notes) > API_LINES:
        shown[-1] += f" (+{len(notes) - API_LINES} more: gymnasium.utils.env_checker.check_env lists them)"
    return [Check("gymnasium API", WARN, n) for n in shown]


def _spaces(env: gym.Env) -> Check:
    obs, act = env.observation_space, env.action_space
    if not isinstance(obs, gym.spaces.Box) or len(obs.shape) != 1:
        return Check("spaces", FAIL, f"the observation space must be a Box, or one Gymnasium can flatten into one "
                                     f"(the MLP's input), got {obs}")
    own = flattened_from(env)
    floats = f"{obs.shape[0]} floats" + ("" if own is None else f" (its {type(own).__name__} observations "
                                                                   f"flattened{_order(own)})")
    if output_width(act) is None:
        return Check("spaces", FAIL, f"the action space must be a flat Box, Discrete, MultiDiscrete or MultiBinary, "
                                     f"got {act}{flat_hint(act)}")
    if is_choice(act):  # the policy's outputs: an argmax per choice, or a sign per bit (actions.py)
        how = {"Discrete": "argmax", "MultiDiscrete": "an argmax per sub-action"}.get(type(act).__name__, "a bit set "
                                                                                        "per positive output")
        zero = "sets no bit" if isinstance(act, gym.spaces.MultiBinary) else f"is action {_zero_text(act)}"
        return Check("spaces", OK, f"observations {floats}; actions {act} ({how}: {output_width(act)} policy "
                                   f"outputs; a zero output {zero})")
    if not (np.isfinite(act.low).all() and np.isfinite(act.high).all()):
        return Check("spaces", FAIL, f"the action Box needs finite bounds (the policy's [-1, 1] output is "
                                     f"rescaled to them), got low {act.low}, high {act.high}")
    return Check("spaces", OK, f"observations {floats}; actions Box({act.shape[0]}) in {_bounds(act)} (the "
                               f"policy's [-1, 1] rescaled)")


def _bounds(act: gym.spaces.Box) -> str:
    """``[-1, 1]`` where every dimension has the same bounds, else each one's (``[0, 5] x [-0.3, 0.3]``; a new
    user's thrust and steering read as one range ``[-0.3, 5]``), past 6 dimensions the lowest and highest."""
    low, high = np.asarray(act.low).ravel(), np.asarray(act.high).ravel()
    if (low == low[0]).all() and (high == high[0]).all():
        return f"[{_num(low[0])}, {_num(high[0])}]"
    if low.size > 6:
        return f"[{_num(low.min())}, {_num(high.max())}] (the bounds differ per dimension)"
    return " x ".join(f"[{_num(lo)}, {_num(hi)}]" for lo, hi in zip(low, high))


def _order(space: gym.Space) -> str:
    """``: a (2), b (4), in that order``: a Dict space's keys and sizes in gymnasium.spaces.flatten's order,
    else ``""``."""
    if isinstance(space, gym.spaces.Dict):
        return ": " + ", ".join(f"{k} ({gym.spaces.flatdim(v)})" for k, v in space.spaces.items()) + ", in that order"
    return ""


def _time_limit(env: gym.Env) -> Check:
    limit = env.spec.max_episode_steps if env.spec is not None else None
    core = get_batch_core(env)
    limit = limit or (int(core.max_steps) if core is not None else None)
    if limit:
        return Check("time limit", OK, f"episodes end after at most {limit} steps")
    return Check("time limit", WARN, "no time limit: PPO needs one (or rollout.max_steps), and an episode that "
                                     "never ends never returns; set rollout.max_steps")


def _threshold(env_id: str, env_kwargs: dict | None) -> Check:
    """The success threshold ``benchmark`` and ``report`` use by default, at these kwargs' reward scale (a new
    user's was missing and nothing said so)."""
    from shaped_es.envs.thresholds import threshold_of

    thr = threshold_of(env_id, env_kwargs)
    if thr is not None:
        return Check("threshold", OK, f"{thr[0]:g}, benchmark's and report's success threshold: {thr[1]}")
    why = ("registered" if not env_kwargs else "at these env settings (a built-in env's settings that change its "
           "reward have none)")
    return Check("threshold", NO, f"no reward_threshold {why} (optional: benchmark then "
                                  "measures success at the best baseline's final reward; register one, or pass "
                                  "--threshold)")


def _episodes(env, env_id, env_kwargs, episodes: int, max_steps: int, seed: int) -> list[Check]:
    """Seeding, finiteness and the waypoint contract from ``episodes`` seeded random-action episodes,
    each run twice (on this env and on a second one made alike)."""
    twin = make_env(env_id, env_kwargs)
    try:
        runs = [_episode(env, seed + e, max_steps) for e in range(episodes)]
        again = [_episode(twin, seed + e, max_steps) for e in range(episodes)]
        # the first episode once more on this env, after the others: an env that carries state from one episode
        # to the next (a NormalizeObservation wrapper) plays it otherwise, and a run's numbers then depend on
        # which worker ran which episode (a new user's: -79.08 inline, -76.99 on two processes)
        later = _episode(env, seed, max_steps)
    finally:
        close_env(twin)
    errors = [r["error"] for r in runs + again + [later] if r["error"]]
    if errors:
        return [Check("steps", FAIL, errors[0])]
    steps = sum(len(r["rewards"]) for r in runs)
    out = [Check("steps", OK, f"{steps} random steps over {episodes} episodes: observations keep their "
                              f"shape, observations and rewards are finite")]
    same = all(_same(a, b) for a, b in zip(runs, again))
    if not same:
        out.append(Check("seeding", WARN, "reset(seed=s) with the same actions gave different episodes: runs do "
                                          "not reproduce and a generation's members do not face the same episodes"))
    elif not _same(runs[0], later):
        out.append(Check("seeding", WARN, "reset(seed=s) with the same actions gave another episode after other "
                                          "episodes on the same env: it carries state from one episode to the next "
                                          "(a NormalizeObservation wrapper, a running statistic?), so a run's "
                                          "numbers depend on which worker ran which episode; reset all such state "
                                          "in reset, and normalize observations with --set es.obs_norm=true"))
    else:
        out.append(Check("seeding", OK, "reset(seed=s) and the same actions give the same episode"))
    out.append(_scale(runs))
    out.append(_waypoints(runs, env, env_id, env_kwargs))
    return out


SCALE_WARN = 1e3  # an observation component this large saturates the policy's tanh units from the first layer


def _scale(runs: list[dict]) -> Check:
    """The observations' magnitude: a component of 1e3 or more (a new user's offset of 1e4) saturates the policy's
    first tanh layer for every member alike, so neither ES nor the clone moves it (the shaped run equalled
    Vanilla-ES to the digit, at -77 after 10 generations against -12.8 without the offset)."""
    obs = np.concatenate([np.stack(r["obs"]).reshape(len(r["obs"]), -1) for r in runs if r["obs"]])  # (T, obs)
    big = np.abs(obs).max(axis=0)  # (obs,)
    if not (big >= SCALE_WARN).any():
        return Check("scale", OK, f"observations within +-{big.max():.3g}")
    i = int(np.argmax(big))
    return Check("scale", WARN, f"observation component {i} reaches {big[i]:.3g} ({int((big >= SCALE_WARN).sum())} "
                                f"of {big.size} reach {SCALE_WARN:g}): the policy's tanh units saturate and no "
                                f"method learns well; scale observations to about 1, or --set es.obs_norm=true")


def _zero_text(space: gym.Space) -> str:
    """The action a zero policy output is in a space of choices: ``0``, ``-1``, ``[0 0]``, ``[-1 -2]``."""
    return str(zero_action(space)).replace("\n", " ")


def _episode(env: gym.Env, seed: int, max_steps: int, act=None) -> dict:
    """One episode of random actions (the action space seeded with ``seed``), or of ``act(obs, info)``'s; what
    came back, or the first problem as ``error``."""
    rec = {"obs": [], "rewards": [], "infos": [], "error": None}
    try:
        obs, info = env.reset(seed=seed)
        env.action_space.seed(seed)
        shape = np.shape(obs)
        declared = getattr(env.observation_space, "shape", None)
        if declared is not None and shape != tuple(declared):  # the rollouts refuse it at generation 0 (a new
            #                        user's arm declared 26 floats and returned 23: check-env said ok, train failed)
            rec["error"] = (f"reset (seed {seed}): an observation of shape {shape}, its observation space says "
                            f"{tuple(declared)}")
            return rec
        for t in range(max_steps + 1):
            o = np.asarray(obs, dtype=np.float64)
            if o.shape != shape:
                rec["error"] = f"step {t}: observation shape {o.shape}, reset gave {shape}"
                break
            if not np.isfinite(o).all():
                rec["error"] = f"step {t} (seed {seed}): non-finite observation"
                break
            rec["obs"].append(o)
            rec["infos"].append(info)
            if t == max_steps:
                break
            if act is None:
                a = env.action_space.sample()
            else:
                try:
                    a = act(obs, info)
                except Exception as exc:  # noqa: BLE001 - the controller's own error, as one line
                    rec["error"] = f"it raised {type(exc).__name__}: {_line(str(exc))} (seed {seed}, step {t})"
                    break
                problem = action_problem(env.action_space, a)
                if problem:  # the rollouts refuse it too (a gear out of range would become another option's label)
                    rec["error"] = (f"it returned {action_text(a)}, not an action of {env.action_space} "
                                    f"({problem}; seed {seed}, step {t})")
                    break
                a = np.asarray(a, env.action_space.dtype)
            obs, reward, terminated, truncated, info = env.step(a)
            try:  # the rollouts' own rule: a real number or an array of one
                r = one_reward(reward)
            except BadOutput:
                r = None
            if r is None or not np.isfinite(r):
                rec["error"] = f"step {t + 1} (seed {seed}): reward {reward!r} is not a finite number"
                break
            rec["rewards"].append(r)
            if terminated or truncated:
                rec["obs"].append(np.asarray(obs, dtype=np.float64))
                rec["infos"].append(info)
                break
    except Exception as exc:  # noqa: BLE001 - the env raised: reported as one line
        rec["error"] = f"the env raised {type(exc).__name__}: {_line(str(exc))} (seed {seed})"
    return rec


def _same(a: dict, b: dict) -> bool:
    return (len(a["obs"]) == len(b["obs"]) and all(np.array_equal(x, y) for x, y in zip(a["obs"], b["obs"]))
            and a["rewards"] == b["rewards"])


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


def _controller(env: gym.Env, max_steps: int = 200) -> Check:
    """The optional scripted waypoint controller (the oracle label source, ``envs/core.py``); on an env's own
    hook (not a batched core's), what it returns against zero action and random actions (a new user measured
    these by hand to set a threshold)."""
    if has_controller(env):
        detail = "waypoint_controller(obs, info): the oracle labels (shaping.labels=controller) can use it"
        hook = getattr(getattr(env, "unwrapped", env), "waypoint_controller", None)
        if get_batch_core(env) is None and callable(hook):  # Discrete too: its zero action is action 0
            text, drove = _returns_text(env, hook, max_steps)
            if not drove:  # a new user's controller raised or returned no action, and the line said "ok"
                return Check("controller", WARN, f"waypoint_controller(obs, info) cannot drive the env as it is (the "
                                                 f"oracle labels, shaping.labels=controller, would stop the run){text}")
            detail += text
        return Check("controller", OK, detail)
    return Check("controller", NO, "no waypoint_controller(obs, info) (optional: the oracle label source "
                                   "shaping.labels=controller needs one)")


RETURN_EPISODES = 10  # episodes of each policy in the controller's line (seeds 0..9), in rounds of this many
RETURN_MAX = 50  # ... while the rounds so far took under RETURN_BUDGET_S seconds (two new users' bodies, whose
RETURN_BUDGET_S = 3.0  # returns scale with a random goal distance: 10 episodes' thresholds moved by 10-20%)


def _returns_text(env: gym.Env, hook, max_steps: int) -> tuple[str, bool]:
    """``; returns over 30 episodes: it 9.30, zero action 0.00, random actions -1.92 (a threshold: 8.37 +- 0.21,
    90% of the way from zero action's return to its own, as the suite's were set; +-: 2 standard errors over the
    episodes)``, or where the controller raised, that one line. Rounds of ``RETURN_EPISODES`` seeds (0, 1, ...)
    while they take under ``RETURN_BUDGET_S`` in all, up to ``RETURN_MAX`` episodes; and whether the episodes ran."""
    space = env.action_space
    limit = getattr(getattr(env, "spec", None), "max_episode_steps", None) or max_steps
    middle = zero_action(space)  # the policy's zero output, as the rollouts map it
    policies = {"it": hook, "zero action": lambda o, i: middle, "random actions": None}
    returns: dict[str, list[float]] = {name: [] for name in policies}
    t0 = time.perf_counter()
    while True:
        seeds = range(len(returns["it"]), len(returns["it"]) + RETURN_EPISODES)
        for name, act in policies.items():
            runs = [_episode(env, seed, limit, act) for seed in seeds]
            failed = next((r["error"] for r in runs if r["error"]), None)
            if failed:  # one line
                return f"; driving it over an episode: {failed}", False
            returns[name] += [float(sum(r["rewards"])) for r in runs]
        n = len(returns["it"])
        if n >= RETURN_MAX or time.perf_counter() - t0 > RETURN_BUDGET_S:
            break
    means = {k: float(np.mean(v)) for k, v in returns.items()}
    it, zero = means["it"], means["zero action"]
    per = suggested_threshold(np.array(returns["it"]), np.array(returns["zero action"]))  # (n,) paired by seed
    spread = 2 * float(np.std(per, ddof=1)) / np.sqrt(n)
    return (f"; returns over {n} episodes: it {it:.2f}, zero action {zero:.2f}, random actions "
            f"{means['random actions']:.2f} (a threshold: {suggested_threshold(it, zero):.2f} +- {spread:.2f}, 90% of "
            f"the way from zero action's return to its own, as the suite's were set; +-: 2 standard errors over the "
            f"episodes)"), True


def suggested_threshold(controller: float, zero: float) -> float:
    """90% of the way from zero action's return to the controller's: 0.9 x the controller's where zero action
    returns 0 (the suite's progress rewards); where returns are negative (a distance penalty), 0.9 x the
    controller's would ask for more than the controller does."""
    return zero + 0.9 * (controller - zero)


def _line(text: str) -> str:
    return " ".join(_ANSI.sub("", text).split())


def _num(x: float) -> str:
    return f"{float(x):g}"


def as_dicts(checks: list[Check]) -> list[dict]:
    return [asdict(c) for c in checks]
