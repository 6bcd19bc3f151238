"""Transitions recorded by rollouts: the data that trains the inverse-dynamics model (paper, Sec. III).

One :class:`Transitions` holds every step of one population member's episodes, row per step:
``(s_t, position_t, waypoint_t, a_t, r_t)``. ``position`` and ``waypoint`` come from the env contract
(``envs/core.py``); envs without it leave them as zero-width arrays ``(T, 0)``. ``expert`` (optional)
holds the env's waypoint controller's action at ``s_t`` (the ``controller`` label source,
``shaping/labels.py``), recorded only when a rollout asks for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

COLUMNS = ("generation", "member", "episode", "step", "state", "position", "waypoint", "action", "reward")


@dataclass
class Transitions:
    """Steps of one member's episodes, concatenated in (episode, step) order."""

    generation: int
    member: int
    episode: np.ndarray  # (T,) int32, episode index within the member (0..E-1)
    step: np.ndarray  # (T,) int32, time step t within its episode
    state: np.ndarray  # (T, obs_dim) float32, s_t
    position: np.ndarray  # (T, d) float32, agent position at t (waypoint space)
    waypoint: np.ndarray  # (T, d) float32, next local waypoint at t
    action: np.ndarray  # (T, act_dim) float32, a_t in [-1, 1]
    reward: np.ndarray  # (T,) float32, r_t
    expert: np.ndarray | None = None  # (T, act_dim) float32, the env controller's action at s_t (optional)

    def __len__(self) -> int:
        return int(self.step.shape[0])

    def episode_returns(self) -> np.ndarray:
        """Cumulative reward per episode, ``(E,)`` in episode order."""
        eps = np.unique(self.episode)
        return np.array([self.reward[self.episode == e].sum() for e in eps], dtype=np.float64)

    def next_position(self) -> tuple[np.ndarray, np.ndarray]:
        """``(mask, position_{t+1})``: mask ``(T,)`` is True where step t+1 of the same episode exists."""
        same = (self.episode[1:] == self.episode[:-1]) & (self.step[1:] == self.step[:-1] + 1)
        mask = np.zeros(len(self), dtype=bool)
        mask[:-1] = same
        nxt = np.zeros_like(self.position)
        nxt[:-1] = self.position[1:]
        return mask, nxt


def concat_members(trs: list[Transitions]) -> tuple[Transitions, np.ndarray]:
    """One generation's members as one :class:`Transitions` (member ``-1``; episode ids made unique as
    ``position in trs * E + episode``) and the row offsets ``(len(trs) + 1,)`` of each member in it, so
    per-step functions run once per generation instead of once per member."""
    lens = np.array([len(t) for t in trs], np.int64)
    offsets = np.concatenate([[0], np.cumsum(lens)])  # (k + 1,)
    if not trs:
        raise ValueError("concat_members needs at least one member")
    E = 1 + max((int(t.episode.max()) for t in trs if len(t)), default=0)
    cat = np.concatenate
    episode = cat([t.episode.astype(np.int64) + i * E for i, t in enumerate(trs)])
    return Transitions(
        generation=trs[0].generation, member=-1, episode=episode, step=cat([t.step for t in trs]),
        state=cat([t.state for t in trs]), position=cat([t.position for t in trs]),
        waypoint=cat([t.waypoint for t in trs]), action=cat([t.action for t in trs]),
        reward=cat([t.reward for t in trs]),
        expert=cat([t.expert for t in trs]) if all(t.expert is not None for t in trs) else None,
    ), offsets
