"""The task the planar bodies share: settings, episode sampling, spatial line waypoints and the reward.

Episode. Start uniform in ``[-arena, arena]^2``; goal at a distance ``d0 ~ U(goal_distance)`` in a
uniform direction; a start heading uniform in ``[-pi, pi)`` (the unicycle's; the points ignore it). One
generator per episode, seeded by the episode seed, draws them in this order, so a seed gives the same
start and goal on every planar body.

Waypoints (spatial: consumed when reached). Points ``start + min(k * spacing, d0) * u`` for
``k = 1 .. N = ceil(d0 / spacing)`` on the start-goal line (``u`` its direction; the last one is the
goal). ``index`` is the next one not yet consumed; after every step it advances past every waypoint the
agent's projection on the line has passed, then past every one within ``reach_radius`` of the agent (so
the next waypoint always lies ahead along the line). Once all are consumed, the waypoint is the goal.

Reward (dense progress). ``reward_progress = progress_reward * (|p_t - g| - |p_{t+1} - g|) / d0`` (the
whole way to the goal pays ``progress_reward`` whatever its length) plus ``reward_step = -step_penalty``
every step. The episode terminates once the agent is within ``goal_radius`` of the goal
(``is_success``) and is truncated after ``max_steps``. Returns are at most ``progress_reward``; standing
still earns ``-step_penalty * max_steps``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class PlanarTaskConfig:
    """Settings every planar body shares (lengths in arena units, one step = ``dt`` seconds)."""

    max_steps: int = 100  # the episode is truncated after this many steps
    arena: float = 1.0  # start uniform in [-arena, arena]^2
    goal_distance: tuple[float, float] = (0.5, 1.5)  # start-goal distance range
    waypoint_spacing: float = 0.1  # a waypoint every this far along the start-goal line
    reach_radius: float = 0.05  # a waypoint within this distance of the agent is consumed
    goal_radius: float = 0.05  # the episode ends (success) within this distance of the goal
    progress_reward: float = 10.0  # the whole way from start to goal pays this much
    step_penalty: float = 0.01  # reward -step_penalty every step
    terminate_at_goal: bool = True  # end the episode at the goal
    dt: float = 0.1  # seconds per step (rendering frame rate; the bodies' dynamics use it)

    def validate(self):
        lo, hi = self.goal_distance
        checks = [
            (self.max_steps > 0, "max_steps must be positive"),
            (self.arena >= 0, "arena must be >= 0"),
            (len(self.goal_distance) == 2 and 0 < lo <= hi, "goal_distance must be 0 < lo <= hi"),
            (self.waypoint_spacing > 0, "waypoint_spacing must be positive"),
            (self.reach_radius > 0 and self.goal_radius > 0, "reach_radius and goal_radius must be positive"),
            (self.dt > 0, "dt must be positive"),
            (self.step_penalty >= 0, "step_penalty must be >= 0"),
        ]
        for ok, msg in checks:
            if not ok:
                raise ValueError(f"{type(self).__name__}: {msg}")
        return self

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


def sample_episodes(seeds: np.ndarray, cfg: PlanarTaskConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(start (B, 2), goal (B, 2), heading (B,))``, one generator per episode seed."""
    seeds = np.asarray(seeds, dtype=np.int64).reshape(-1)
    B = seeds.shape[0]
    start, goal, heading = np.empty((B, 2)), np.empty((B, 2)), np.empty(B)
    for i, s in enumerate(seeds):
        rng = np.random.default_rng(int(s))
        start[i] = rng.uniform(-cfg.arena, cfg.arena, 2)
        d, phi = rng.uniform(*cfg.goal_distance), rng.uniform(-math.pi, math.pi)
        goal[i] = start[i] + d * np.array([math.cos(phi), math.sin(phi)])
        heading[i] = rng.uniform(-math.pi, math.pi)
    return start, goal, heading


def num_waypoints(start: np.ndarray, goal: np.ndarray, spacing: float) -> np.ndarray:
    """``N = ceil(d0 / spacing)`` waypoints per episode, ``(B,)`` int64."""
    d0 = np.linalg.norm(goal - start, axis=1)  # (B,)
    return np.ceil(d0 / spacing - 1e-9).astype(np.int64)


def line_waypoint(start: np.ndarray, goal: np.ndarray, index: np.ndarray, spacing: float) -> np.ndarray:
    """Waypoint ``index`` (0-based: the ``index + 1``-th point) of each episode's line, ``(B, 2)``; the
    goal once ``index >= N``."""
    d = goal - start  # (B, 2)
    d0 = np.linalg.norm(d, axis=1)  # (B,)
    s = np.minimum((index + 1) * spacing, d0)  # (B,) distance along the line
    return start + d * (s / d0)[:, None]  # (B, 2)


def advance_index(pos: np.ndarray, start: np.ndarray, goal: np.ndarray, index: np.ndarray,
                  cfg: PlanarTaskConfig) -> np.ndarray:
    """The next waypoint not consumed after the agent moved to ``pos`` (module docstring), ``(B,)``."""
    d = goal - start  # (B, 2)
    d0 = np.linalg.norm(d, axis=1)  # (B,)
    n = num_waypoints(start, goal, cfg.waypoint_spacing)  # (B,)
    s = np.einsum("bi,bi->b", pos - start, d) / d0  # (B,) projection on the line
    passed = np.where(s >= d0, n, np.clip(np.floor(s / cfg.waypoint_spacing + 1e-9), 0, n)).astype(np.int64)
    idx = np.maximum(index, passed)
    for _ in range(int(math.ceil(2 * cfg.reach_radius / cfg.waypoint_spacing)) + 1):  # reachable at once
        near = (idx < n) & (np.linalg.norm(pos - line_waypoint(start, goal, idx, cfg.waypoint_spacing),
                                           axis=1) < cfg.reach_radius)
        if not near.any():
            break
        idx = idx + near
    return idx


def unit_norm(g: np.ndarray) -> np.ndarray:
    """Each row of ``g`` ``(B, 2)`` scaled down to norm at most 1 (its direction kept)."""
    return g / np.maximum(1.0, np.linalg.norm(g, axis=1, keepdims=True))
