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

Its parts: a check's record and statuses (``check_result.py``), the episodes it runs (``check_episode.py``), the
waypoint contract's check (``check_waypoints.py``), the controller's (``check_controller.py``) and how the lines
are written (``check_text.py``).
"""

from __future__ import annotations

import re
import warnings

import gymnasium as gym
import numpy as np

from shaped_es.envs.core import get_batch_core
from shaped_es.actions import flat_hint, is_choice, output_width
from shaped_es.rollout import close_env, flattened_from, make_env
from shaped_es.cli.check_controller import (  # noqa: F401 - all but _controller: re-exported
    RETURN_BUDGET_S, RETURN_EPISODES, RETURN_MAX, _controller, suggested_threshold)
from shaped_es.cli.check_episode import _episode, _same
from shaped_es.cli.check_result import (  # noqa: F401 - as_dicts, trains_with: re-exported
    FAIL, NO, OK, WARN, Check, as_dicts, trains_with)
from shaped_es.cli.check_text import _bounds, _line, _order, _zero_text
from shaped_es.cli.check_waypoints import _waypoints


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
    i = int(np.argmax(big))
    if not (big >= SCALE_WARN).any():  # which component is the largest (a new user could not tell)
        return Check("scale", OK, f"observations within +-{big[i]:.3g} (the largest: component {i})")
    return Check("scale", WARN, f"observation component {i} reaches {big[i]:.3g} ({int((big >= SCALE_WARN).sum())} "
                                f"of {big.size} reach {SCALE_WARN:g}): the policy's tanh units saturate and no "
                                f"method learns well; scale observations to about 1, or --set es.obs_norm=true")
