"""check-env's controller check: whether the env has the optional scripted waypoint controller the oracle
labels use (``shaping.labels=controller``), and on an env's own hook, what it returns against zero action and
random actions over seeded episodes, with the success threshold those returns suggest (:func:`_controller`,
:func:`suggested_threshold`)."""

from __future__ import annotations

import time

import gymnasium as gym
import numpy as np

from shaped_es.envs.core import get_batch_core, has_controller
from shaped_es.actions import zero_action
from shaped_es.cli.check_episode import _episode
from shaped_es.cli.check_result import NO, OK, WARN, Check


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
