"""Transitions recorded by rollouts: the data that trains the inverse-dynamics model (paper, Sec. III).

One :class:`Transitions` holds every step of one population member's episodes, row per step:
``(s_t, position_t, waypoint_t, a_t, r_t)``. ``position`` and ``waypoint`` come from the env contract
(``envs/core.py``); envs without it leave them as zero-width arrays ``(T, 0)``. ``expert`` (optional)
holds the env's waypoint controller's action at ``s_t`` (the ``controller`` label source,
``shaping/labels.py``), recorded only when a rollout asks for it.

:class:`PackedTransitions` holds several members' steps as one block (one array per column and the row
offsets of each member): what a rollout task sends back, so a result crosses a process boundary as a
few large arrays instead of ``9 x members`` small ones, and the master stacks a generation from a few
blocks instead of one part per member.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

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


PER_STEP = ("episode", "step", "state", "position", "waypoint", "action", "reward")  # (T, ...) columns


@dataclass
class PackedTransitions:
    """Several members' steps of one generation as one block: member ``members[j]``'s rows are
    ``offsets[j]:offsets[j+1]`` of ``rows``, in (episode, step) order, as its :class:`Transitions`
    would hold them (``rows.episode`` counts within each member; ``rows.member`` is -1)."""

    rows: Transitions
    members: np.ndarray  # (k,) int64, ascending
    offsets: np.ndarray  # (k + 1,) int64

    def __len__(self) -> int:
        return int(self.offsets[-1])

    @property
    def generation(self) -> int:
        return self.rows.generation

    def lengths(self) -> np.ndarray:
        """Rows of each member, ``(k,)``."""
        return np.diff(self.offsets)

    def unpack(self) -> list[Transitions]:
        """One :class:`Transitions` per member (views of the block's arrays, no copies)."""
        r = self.rows
        return [Transitions(generation=r.generation, member=int(m),
                            **{f: getattr(r, f)[a:b] for f in PER_STEP},
                            expert=None if r.expert is None else r.expert[a:b])
                for m, a, b in zip(self.members, self.offsets[:-1], self.offsets[1:])]

    def nonempty(self) -> PackedTransitions:
        """The same block without its members that have no rows."""
        keep = self.lengths() > 0
        if keep.all():
            return self
        return PackedTransitions(self.rows, self.members[keep], np.concatenate([[0], self.offsets[1:][keep]]))

    def stacked(self) -> Transitions:
        """The block as :func:`concat_members` gives its members (member -1; episode ids made unique
        as ``position in the block * E + episode``); the per-step arrays are shared, not copied."""
        if len(self.members) == 0:
            raise ValueError("concat_members needs at least one member")
        lens = self.lengths()
        ep = self.rows.episode
        E = 1 + (int(ep.max()) if ep.size else 0)
        position = np.repeat(np.arange(len(lens), dtype=np.int64), lens)  # (T,) each row's member position
        return replace(self.rows, member=-1, episode=ep.astype(np.int64) + position * E)


def pack(trs: list[Transitions]) -> PackedTransitions:
    """Members' :class:`Transitions` of one generation (ascending members) as one block (copies once)."""
    if not trs:
        raise ValueError("pack needs at least one member")
    lens = np.array([len(t) for t in trs], np.int64)
    cat = np.concatenate
    rows = Transitions(generation=trs[0].generation, member=-1,
                       **{f: cat([getattr(t, f) for t in trs]) for f in PER_STEP},
                       expert=cat([t.expert for t in trs]) if all(t.expert is not None for t in trs) else None)
    return PackedTransitions(rows, np.array([t.member for t in trs], np.int64), cat([[0], np.cumsum(lens)]))


def join_packed(blocks: list[PackedTransitions]) -> PackedTransitions:
    """Blocks of one generation (say, one per rollout task) as one, members ascending (the blocks may come
    in any order but must not interleave: each task holds a run of consecutive members)."""
    if not blocks:
        raise ValueError("join_packed needs at least one block")
    blocks = sorted(blocks, key=lambda b: int(b.members[0]) if len(b.members) else -1)
    if len(blocks) == 1:
        return blocks[0]
    members = np.concatenate([b.members for b in blocks])
    if (np.diff(members) <= 0).any():
        raise ValueError("join_packed: blocks interleave or repeat members")
    starts = np.cumsum([0] + [len(b) for b in blocks[:-1]])  # (nb,) first row of each block
    offsets = np.concatenate([[0]] + [b.offsets[1:] + s for b, s in zip(blocks, starts)])  # (k + 1,)
    r = [b.rows for b in blocks]
    cat = np.concatenate
    rows = Transitions(generation=r[0].generation, member=-1, **{f: cat([getattr(x, f) for x in r]) for f in PER_STEP},
                       expert=cat([x.expert for x in r]) if all(x.expert is not None for x in r) else None)
    return PackedTransitions(rows, members, offsets.astype(np.int64))
