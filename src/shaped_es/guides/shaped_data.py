"""The shaped method's recorded steps per generation, as the guide reads them: one block per generation
in memory (master placement; ``_Block``), read back from the trajectory store when memory lacks it (a
restart, or the workers placement), and served as the rows the cloning draws (``member_rows``: each
member's ``D_i``; ``dagger_rows``: the mean's DAgger set), trimmed to what the next generation reads.

``GenerationData`` is a part of ``guides/shaped.py``'s ``ShapedGuide`` (its base class), which owns the
state these methods use: ``_cache`` (generation -> ``_Block``), ``_silent`` (generations slept through),
``labels`` (the label source: ``inputs``), ``traj_root``, ``placement``, ``sh`` (the shaping section),
``spec`` and ``_ckpt_margin``; and for the wrap check of the recorded positions (``_check_wrap``) ``run_name``,
``store_root``, ``_wrap_declared``, ``_wrap_warned`` and ``position_period``.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass, field

import numpy as np

from shaped_es.data import PackedTransitions, Transitions, concat_members, pack
from shaped_es.guides.shaped_setup import write_wrap_file
from shaped_es.rollout.periodic import describe, detect_recorded
from shaped_es.shaping.member_rows import MemberRows
from shaped_es.shaping.trajectories import TrajectoryStoreError, read_generation


@dataclass
class _Block:
    """One generation's transitions in memory: all members' rows stacked, in member order."""

    trs: list[Transitions]  # per member (those with steps; views of packed's arrays)
    big: Transitions | None  # trs concatenated (data.concat_members); its state is (N, obs)
    queries: np.ndarray | None  # (N, k) float32 the label source's inputs (M_phi: raw queries w_t - p_t)
    members: np.ndarray  # (k,) member index of each trs entry
    offsets: np.ndarray  # (k + 1,) rows of trs[j] are offsets[j]:offsets[j+1]
    packed: PackedTransitions | None = None  # the same rows as one block (the shard's source)
    # another label source's inputs for these rows (the rival frame's, guides/rival.py), computed once
    other_queries: dict = field(default_factory=dict)

    def queries_for(self, labels) -> np.ndarray:
        """``(N, k)`` what ``labels`` reads besides the state, for this block's rows."""
        if labels not in self.other_queries:
            self.other_queries[labels] = labels.inputs(self.big)
        return self.other_queries[labels]


class GenerationData:
    """The generations' data of a :class:`~shaped_es.guides.shaped.ShapedGuide` (the module docstring
    names the guide's attributes these methods use)."""

    def _remember(self, generation: int, data: list[Transitions] | PackedTransitions | None) -> None:
        """Keep one generation in memory as one block: states, raw queries and each member's rows
        (``data``: per-member transitions in member order, or the rollouts' blocks joined)."""
        packed = data if isinstance(data, PackedTransitions) else None
        if packed is None:
            trs = [t for t in (data or []) if len(t)]
            packed = pack(trs) if trs else None
        else:
            packed = packed.nonempty()
        if packed is None or len(packed.members) == 0:
            self._cache[generation] = _Block([], None, None, np.zeros(0, np.int64), np.zeros(1, np.int64), None)
            return
        big = packed.stacked()  # data.concat_members of its members, sharing the block's arrays
        q = self.labels.inputs(big)  # (N, k) what the label source reads besides the state
        self._cache[generation] = _Block(packed.unpack(), big, q, packed.members, packed.offsets, packed)

    def _check_wrap(self, generation: int, big: Transitions | None) -> None:
        """The first time a generation's recorded positions jump by about a turn (``rollout/periodic.py``), one
        line: a wrapped angle the run's start did not detect (a pendulum only a trained policy swings over the
        cut) is taken the short way from the rollouts that start after this one on (``position_period``, which
        the trainer's tasks carry; checkpointed; ``RUN/position_period.json``), the rows already recorded are
        trained on as they are until they leave the history; a period the env declares that leaves the jumps
        in (a new user's arm declared 360 for radians) is the env's word: a warning only. Rows taken
        continuous never jump, so a right period or a detected one never says anything."""
        if self._wrap_warned or big is None or len(big) < 2:
            return
        period = detect_recorded(big.position, big.next_position()[0])
        if period is None:
            return
        self._wrap_warned = True
        if self._wrap_declared:
            how = describe(period, True, "the env's position_period leaves it out")
            print(f"shaped-es: {self.run_name}: warning: generation {generation + 1}'s recorded {how}; its steps and w - p are "
                  f"trained on as they are (the long way round across the cut): check env.unwrapped.position_period "
                  f"(README: Angles that wrap)", file=sys.stderr)
            return
        self.position_period = np.asarray(period, np.float64)  # (d,)
        write_wrap_file(self.store_root, self.position_period, False, generation)
        print(f"shaped-es: {self.run_name}: generation {generation + 1}'s recorded "
              f"{describe(period, True, 'not seen by the start of the run')}: the next rollouts record it continuous "
              f"and take each step and w - p the short way; the {self.sh.history} generations' rows M_phi and the "
              f"clones read already hold the jumps until they age out (declare env.unwrapped.position_period to "
              f"have it from the start; README: Angles that wrap)", file=sys.stderr)

    def _generation(self, generation: int) -> list[Transitions]:
        """Every member's transitions of ``generation``: from memory (master placement) or the store."""
        if generation in self._silent and generation not in self._cache:
            self._remember(generation, [])  # slept through (label_budget.py): nothing was recorded
            return []
        if generation not in self._cache:
            trs = read_generation(self.traj_root, generation)
            if not trs:  # every generation's rollouts write a shard: this one was lost
                raise TrajectoryStoreError(
                    f"generation {generation + 1}'s trajectories (gen_{generation:06d}) are missing from "
                    f"{self.traj_root} (deleted?); the shaped method needs them to continue; restore them or start "
                    f"a new run")
            if self.placement == "workers":
                return trs
            self._remember(generation, trs)
        return self._cache[generation].trs

    def history_generations(self, generation: int) -> list[int]:
        """The generations whose data the clones of generation ``generation`` read (``shaping.history``)."""
        return list(range(max(0, generation - self.sh.history + 1), generation + 1))

    def member_rows(self, gens: list[int], P: int) -> MemberRows:
        """``D_i`` of every member ``i < P`` over ``gens`` as spans of the cached blocks (no copies; after
        a restart, what memory lacks is read from the store first)."""
        for g in gens:
            self._generation(g)
        blocks = [self._cache[g] for g in gens if self._cache[g].trs]
        spans = np.zeros((P, max(1, len(blocks)), 2), np.int64)  # (P, nb, 2)
        for b, blk in enumerate(blocks):
            ok = blk.members < P
            spans[blk.members[ok], b, 0] = blk.offsets[:-1][ok]
            spans[blk.members[ok], b, 1] = blk.offsets[1:][ok]
        if not blocks:
            return MemberRows([np.zeros((0, self.spec.obs_dim), np.float32)], [np.zeros((0, 0), np.float32)],
                              spans)
        return MemberRows([blk.big.state for blk in blocks], [blk.queries for blk in blocks], spans)

    def dagger_rows(self, generation: int, labels=None) -> MemberRows:
        """Every recorded step of the last ``history`` generations up to ``generation`` as the rows of one
        data set (``MemberRows`` with one member, oldest block first): the mean's DAgger set; ``labels``: a
        label source other than the guide's (the rival's, ``guides/rival.py``), whose inputs are computed
        here instead of read from the blocks."""
        gens = self.history_generations(generation)
        labels = self.labels if labels is None else labels
        if self.placement == "workers":  # nothing in memory: read the generations' shards
            trs = [t for g in gens for t in self._generation(g) if len(t)]
            if not trs:
                return MemberRows.from_lists([np.zeros((0, self.spec.obs_dim), np.float32)],
                                             [np.zeros((0, 0), np.float32)])
            big, _ = concat_members(trs)
            return MemberRows.from_lists([big.state], [labels.inputs(big)])
        for g in gens:
            self._generation(g)
        blocks = [self._cache[g] for g in gens if self._cache[g].trs]
        if not blocks:
            return MemberRows.from_lists([np.zeros((0, self.spec.obs_dim), np.float32)],
                                         [np.zeros((0, 0), np.float32)])
        spans = np.array([[[0, blk.offsets[-1]] for blk in blocks]], np.int64)  # (1, nb, 2): whole blocks
        queries = [blk.queries if labels is self.labels else blk.queries_for(labels) for blk in blocks]
        return MemberRows([blk.big.state for blk in blocks], queries, spans)

    def _trim_cache(self, generation: int) -> None:
        """Memory keeps what the next generation reads: ``g`` (M_phi) and ``g-history+2 .. g`` (D_i)."""
        keep_from = generation + 2 - max(self.sh.history, 2)
        for g in [g for g in self._cache if g < keep_from]:
            del self._cache[g]
        self._silent = {g for g in self._silent if g >= keep_from - self._ckpt_margin}

