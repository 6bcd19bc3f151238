"""The environment contract shared by every method, and the batched-core protocol of built-in envs.

Contract for *any* Gymnasium env (a user's own included) trained with ``--method shaped``:

=====================  ==========================  =============================================
``info`` key           shape / dtype               meaning
=====================  ==========================  =============================================
``"position"``         ``(d,)`` float              the agent's current position in waypoint space
``"waypoint"``         ``(d,)`` float              the next local waypoint the agent should reach
=====================  ==========================  =============================================

Both keys must be present in the ``info`` of ``reset`` *and* of every ``step``. The policy never sees
them (they are not part of the observation); only the inverse-dynamics model ``M_phi(s_t, w_t)`` of the
paper (Sec. III) uses them, at train time. Vanilla-ES, CMA-ES and PPO ignore them.

A position that wraps (a heading in ``(-pi, pi]``): ``env.unwrapped.position_period`` says so (one period, or one
per coordinate, ``None`` where a coordinate does not wrap; ``None``: nothing wraps), else it is detected; a shaped
run records it continuous and takes ``w - p`` the short way (``rollout/periodic.py``).

Built-in envs additionally expose a *batched core* (``env.unwrapped.batch_core``): a pure object that
steps ``B`` independent copies at once, ``state in -> state out``, with NumPy arrays. The rollout layer
uses it when present, so a whole chunk of the population runs in one vectorized loop. Protocol:

- ``reset(seeds)``: ``seeds`` ``(B,)`` int64 -> ``(state, obs (B, obs_dim) float32, info)``
- ``step(state, action)``: ``action`` ``(B, act_dim)`` float32 in ``[-1, 1]`` ->
  ``(state, obs, reward (B,) float64, terminated (B,) bool, truncated (B,) bool, info)``

``info`` holds ``(B, ...)`` arrays: ``"position"`` ``(B, d)``, ``"waypoint"`` ``(B, d)`` and one
``"reward_<term>"`` ``(B,)`` per named reward term, the terms summing to ``reward``. All randomness of an
episode comes from its seed at ``reset``; ``step`` is deterministic. Stepping an env that has already
ended is allowed (its outputs are ignored by the caller).

Optional hook, a scripted **waypoint controller** (the ``controller`` label source of ``--method shaped``,
``shaping.labels=controller``: the oracle that measures what labels can give a search at most):

- a Gymnasium env: ``env.unwrapped.waypoint_controller(obs, info) -> action``, an action of the env's own
  action space for the observation and ``info`` it just returned (``info`` carries the contract's keys);
- a batched core: ``core.waypoint_controller(state, obs, info) -> (B, act_dim)`` float32 in ``[-1, 1]``.

CarNav-v0 offers pure pursuit of ``info["waypoint"]`` (``carnav/controller.py``), UR5Reach-v0 resolved-rate
control toward it (``ur5/controller.py``). A controller may read the env's full state: it is used only to
label training states, never at test time.
"""

from __future__ import annotations

import difflib
from typing import Any, Protocol, runtime_checkable

import numpy as np

POSITION_KEY = "position"
WAYPOINT_KEY = "waypoint"
# ``env.metadata[SERIAL_EPISODES_KEY] = True``: instances of the env in one process share one simulator
# (CarlaNav-v0: one CARLA server per worker), so their episodes must run one after another, never in
# lock-step (``rollout`` and PPO's test episodes honour it).
SERIAL_EPISODES_KEY = "serial_episodes"
REWARD_TERM_PREFIX = "reward_"
EPISODE_SEED_HIGH = 2**63 - 1  # an env reset without a seed draws its episode seed as np_random.integers(this)


def contract_key_guess(missing: list[str], keys) -> list[str]:
    """The info's own keys that look like the contract's ``missing`` ones (a new user's env said ``waypoints``):
    one close match per missing key, for a "did you mean" in the error lines."""
    others = sorted({k for k in keys if isinstance(k, str)} - {POSITION_KEY, WAYPOINT_KEY})
    return [c for k in missing for c in difflib.get_close_matches(k, others, n=1, cutoff=0.7)]


@runtime_checkable
class BatchCore(Protocol):
    """Steps ``B`` copies of an environment at once; see the module docstring for the contract."""

    obs_dim: int
    act_dim: int
    pos_dim: int
    max_steps: int

    def reset(self, seeds: np.ndarray) -> tuple[Any, np.ndarray, dict[str, np.ndarray]]: ...

    def step(
        self, state: Any, action: np.ndarray
    ) -> tuple[Any, np.ndarray, np.ndarray, np.ndarray, np.ndarray, dict[str, np.ndarray]]: ...


def get_batch_core(env: Any) -> BatchCore | None:
    """The env's batched core if it offers one (``env.unwrapped.batch_core``) and nothing wraps it but what
    ``gymnasium.make`` adds (:func:`transparent`), else ``None``. A built-in env under a user's wrapper (an
    observation without the world pose, a scaled reward) runs through that wrapper, episode by episode: the core
    steps the unwrapped env, and would skip it (a wrapped observation's width then failed the policy's product;
    a wrapped reward was silently not counted)."""
    core = getattr(getattr(env, "unwrapped", env), "batch_core", None)
    return core if isinstance(core, BatchCore) and transparent(env, core.max_steps) else None


def transparent(env: Any, max_steps: int) -> bool:
    """Whether every wrapper around ``env.unwrapped`` is one ``gymnasium.make`` adds (order enforcing, the passive
    env checker) or a time limit no shorter than the core's ``max_steps`` (the batched loop's own limit)."""
    import gymnasium as gym

    e = env
    while isinstance(e, gym.Wrapper):
        if isinstance(e, gym.wrappers.TimeLimit):
            if e._max_episode_steps < max_steps:
                return False
        elif not isinstance(e, (gym.wrappers.OrderEnforcing, gym.wrappers.PassiveEnvChecker)):
            return False
        e = e.env
    return True


CONTROLLER_HOOK = "waypoint_controller"


def has_controller(env: Any) -> bool:
    """True if the env offers the optional scripted waypoint controller (module docstring): through its
    batched core when it has one, else ``env.unwrapped.waypoint_controller``."""
    core = get_batch_core(env)
    if core is not None:
        return callable(getattr(core, CONTROLLER_HOOK, None))
    return callable(getattr(getattr(env, "unwrapped", env), CONTROLLER_HOOK, None))


def runs_serially(env: Any) -> bool:
    """True if the env's episodes must not run in lock-step with others of the same process."""
    return bool(getattr(env, "metadata", None) and env.metadata.get(SERIAL_EPISODES_KEY, False))


def has_waypoint_contract(info: dict[str, Any]) -> bool:
    """True if an ``info`` dict carries the two keys the shaped method needs."""
    return POSITION_KEY in info and WAYPOINT_KEY in info


def limited_entry_point(env_cls):
    """A registration entry point: ``env_cls(**kwargs)`` under a ``TimeLimit`` of its config's
    ``max_steps``, so the limit follows ``preset`` and overrides, which a fixed ``max_episode_steps``
    could not; carries ``env_cls.metadata`` (``gymnasium.make`` reads the render modes there)."""
    import gymnasium as gym

    def make_limited(**kwargs):
        env = env_cls(**kwargs)
        return gym.wrappers.TimeLimit(env, env.config.max_steps)

    make_limited.metadata = env_cls.metadata
    make_limited.__doc__ = f"``{env_cls.__name__}(**kwargs)`` under a ``TimeLimit`` of its config's max_steps."
    return make_limited
