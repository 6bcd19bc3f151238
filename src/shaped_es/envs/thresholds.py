"""The success threshold of an env: the test reward that counts as solved, and where it comes from.

A built-in env's (``envs.BUILTIN``: the ``reward_threshold`` registered with its EnvSpec, its reason in the env
module's docstring; CarNav-v0's and UR5Reach-v0's in :data:`DEFAULT_THRESHOLDS`), else the ``reward_threshold``
of any other env's Gymnasium spec, a user's env's included. ``benchmark`` counts runs against it, ``train``
says when a run first reaches it, and a shaped run's back-off note says when the run is already past it: one
source for all three, here in the env layer so that none of them reads another's.
"""

from __future__ import annotations

import math

# Success thresholds of the built-in envs at their default reward scale (any preset or env setting that
# rescales the reward, e.g. preset=paper or max_steps, falls back to the best baseline's final mean):
# - CarNav-v0: +M/H per route waypoint, M = 250 over the whole route, -0.1 a step: 200 = the route
#   driven to (nearly) its end; stalling or crashing scores about -25 (docs/benchmarks/carnav).
# - UR5Reach-v0: +1 per Bezier waypoint (M = H = 100), -0.1 a step, -50 on a collision: 40 = half the
#   path followed without a collision (the hand-written follower scores 90, standing still about -4);
#   in docs/benchmarks/ur5 the final rewards of 3 seeds x 3 methods spread 9.6-61.9 and 7 of 9 end above it.
DEFAULT_THRESHOLDS = {
    "CarNav-v0": (200.0, "CarNav-v0 default: the route driven"),
    "UR5Reach-v0": (40.0, "UR5Reach-v0 default: half the Bezier path followed without a collision"),
}
REWARD_SCALE_KEYS = ("preset", "max_steps", "num_waypoints", "step_penalty", "collision_penalty")


def env_threshold(cfg) -> tuple[float, str] | None:
    """The env's default success threshold at a run config's (``cfg.env``, ``cfg.env_kwargs``) reward scale
    (:func:`threshold_of`); None for no config."""
    return None if cfg is None else threshold_of(cfg.env, cfg.env_kwargs)


def threshold_of(env_id: str, env_kwargs: dict | None = None) -> tuple[float, str] | None:
    """The default success threshold of ``env_id`` made with ``env_kwargs``, if it has one at that reward
    scale: a built-in env's (:func:`builtin_threshold`), else the ``reward_threshold`` of any other env's
    Gymnasium spec."""
    env = env_id.rsplit(":", 1)[-1]
    from shaped_es.envs import BUILTIN

    if env in BUILTIN:
        kwargs = env_kwargs or {}
        rescaled = [k for k in REWARD_SCALE_KEYS if k in kwargs and not (k == "preset" and kwargs[k] == "default")]
        return None if rescaled else builtin_threshold(env)
    return spec_threshold(env_id)


def spec_threshold(env_id: str) -> tuple[float, str] | None:
    """The ``reward_threshold`` registered with the Gymnasium spec of ``env_id`` (``module:Id``: the module
    imported first, as making the env does) and where it comes from; None when the spec has none or the
    id cannot be looked up here."""
    import importlib

    import gymnasium as gym

    module, _, name = env_id.rpartition(":")
    try:
        if module:
            importlib.import_module(module)
        thr = gym.spec(name).reward_threshold
    except (Exception, SystemExit):  # noqa: BLE001 - not importable or registered here: none of its own
        return None
    if thr is None or not math.isfinite(float(thr)):
        return None
    return float(thr), f"{env_id} reward_threshold (registered with its Gymnasium spec)"


def builtin_threshold(env: str) -> tuple[float, str] | None:
    """A built-in env's success threshold at its default reward scale and where it comes from: the
    ``reward_threshold`` registered with its EnvSpec (``envs.BUILTIN``; its reason in the env module's
    docstring), CarNav-v0's and UR5Reach-v0's with their reasons here. None for any other env."""
    from shaped_es.envs import BUILTIN

    env = env.rsplit(":", 1)[-1]
    if env in DEFAULT_THRESHOLDS:
        return DEFAULT_THRESHOLDS[env]
    entry = BUILTIN.get(env)
    if entry is None or entry[2] is None:
        return None
    return float(entry[2]), f"{env} reward_threshold (registered; its reason in the env's docstring)"
