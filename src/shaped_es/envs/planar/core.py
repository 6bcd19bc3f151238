"""Batched core of the planar bodies (``envs/core.py`` protocol): the shared task of ``task.py`` stepped for
``B`` episodes at once, state in -> state out; a body subclass supplies ``move`` (its dynamics),
``observe`` (its observation) and ``waypoint_controller`` (its oracle).

State: position, velocity (the force-controlled point's; zero for the others), heading (the unicycle's;
the start heading for the points, unused), start, goal, waypoint index, steps, done. Action ``(B, 2)`` in
``[-1, 1]``. ``info``: ``position`` ``(B, 2)``, ``waypoint`` ``(B, 2)``, ``goal``, ``waypoint_index``,
``num_waypoints``, ``is_success`` and the reward terms ``reward_progress``, ``reward_step``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shaped_es.envs.planar.task import (PlanarTaskConfig, advance_index, line_waypoint, num_waypoints,
                                        sample_episodes)


@dataclass(frozen=True)
class PlanarState:
    """Explicit state of ``B`` episodes; ``step`` never mutates it."""

    pos: np.ndarray  # (B, 2) float64
    vel: np.ndarray  # (B, 2) float64, velocity (units / s; PointForce only, else zeros)
    heading: np.ndarray  # (B,) float64, radians (Unicycle's body; the points carry it unused)
    start: np.ndarray  # (B, 2)
    goal: np.ndarray  # (B, 2)
    index: np.ndarray  # (B,) int64, next waypoint not yet consumed
    steps: np.ndarray  # (B,) int64
    done: np.ndarray  # (B,) bool

    @property
    def batch_size(self) -> int:
        return int(self.pos.shape[0])


class PlanarCore:
    """The shared task over a body; subclasses set ``obs_dim`` and define the three body methods."""

    obs_dim: int
    act_dim = 2
    pos_dim = 2

    def __init__(self, config: PlanarTaskConfig):
        self.config = config.validate()
        self.max_steps = config.max_steps

    # --- the body ---------------------------------------------------------------------------------
    def move(self, state: PlanarState, act: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(pos, vel, heading)`` after one step of ``act`` ``(B, 2)`` in ``[-1, 1]``."""
        raise NotImplementedError

    def observe(self, state: PlanarState) -> np.ndarray:
        """The policy's observation ``(B, obs_dim)`` float32 (no waypoints)."""
        raise NotImplementedError

    def waypoint_controller(self, state: PlanarState, obs: np.ndarray, info: dict) -> np.ndarray:
        raise NotImplementedError

    # --- the protocol -----------------------------------------------------------------------------
    def waypoint(self, state: PlanarState) -> np.ndarray:
        return line_waypoint(state.start, state.goal, state.index, self.config.waypoint_spacing)  # (B, 2)

    def _info(self, state: PlanarState) -> dict[str, np.ndarray]:
        return {"position": state.pos.copy(), "waypoint": self.waypoint(state), "goal": state.goal.copy(),
                "waypoint_index": state.index.copy(),
                "num_waypoints": num_waypoints(state.start, state.goal, self.config.waypoint_spacing)}

    def reset(self, seeds: np.ndarray):
        start, goal, heading = sample_episodes(seeds, self.config)
        B = start.shape[0]
        state = PlanarState(pos=start.copy(), vel=np.zeros((B, 2)), heading=heading, start=start, goal=goal,
                            index=np.zeros(B, dtype=np.int64), steps=np.zeros(B, dtype=np.int64),
                            done=np.zeros(B, dtype=bool))
        return state, self.observe(state), self._info(state)

    def step(self, state: PlanarState, action: np.ndarray):
        cfg = self.config
        B = state.batch_size
        act = np.clip(np.asarray(action, dtype=np.float64).reshape(B, 2), -1.0, 1.0)  # (B, 2)
        alive = ~state.done  # (B,)
        pos, vel, heading = self.move(state, act)
        pos = np.where(alive[:, None], pos, state.pos)  # ended episodes stay as they were
        vel = np.where(alive[:, None], vel, state.vel)
        heading = np.where(alive, heading, state.heading)
        d0 = np.linalg.norm(state.goal - state.start, axis=1)  # (B,)
        d_prev = np.linalg.norm(state.pos - state.goal, axis=1)
        d_now = np.linalg.norm(pos - state.goal, axis=1)
        r_prog = np.where(alive, cfg.progress_reward * (d_prev - d_now) / d0, 0.0)  # dense progress
        r_step = np.where(alive, -cfg.step_penalty, 0.0)
        index = np.where(alive, advance_index(pos, state.start, state.goal, state.index, cfg), state.index)
        steps = state.steps + alive
        success = alive & (d_now < cfg.goal_radius)
        terminated = success & cfg.terminate_at_goal
        truncated = alive & ~terminated & (steps >= cfg.max_steps)
        new = PlanarState(pos=pos, vel=vel, heading=heading, start=state.start, goal=state.goal, index=index,
                          steps=steps, done=state.done | terminated | truncated)
        info = {**self._info(new), "is_success": success, "reward_progress": r_prog, "reward_step": r_step}
        return new, self.observe(new), r_prog + r_step, terminated, truncated, info
