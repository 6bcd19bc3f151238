"""What a rollout is given and gives back: :class:`RolloutTask` (a chunk of members and their episode
seeds) and :class:`RolloutResult` (their returns, lengths and recorded steps), the tasks of a population
or of one policy's test episodes, and the result a rollout loop builds from its arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from shaped_es.data import PackedTransitions, Transitions, pack
from shaped_es.policies import MLPSpec, ObsNorm


@dataclass
class RolloutTask:
    """A chunk of members to evaluate. Picklable (crosses process boundaries as a task, never to disk)."""

    env_id: str
    env_kwargs: dict
    spec: MLPSpec
    params: np.ndarray  # (m, n) float32, one row per member
    members: np.ndarray  # (m,) int, population index of each row
    seeds: np.ndarray  # (m, E) int64, episode seeds
    generation: int = 0
    # keep per-step transitions (for the inverse-dynamics model): every member, or a mask (m,) of them
    record: bool | np.ndarray = False
    max_steps: int | None = None  # cap on episode length (None: the env's own limit)
    expert: bool = False  # also record the env's waypoint controller's action (envs/core.py hook)
    rowwise: bool = False  # each observation's action on its own, bit for bit (policies.forward; evaluate)
    obs_norm: ObsNorm | None = None  # the policies' input normalization (es.obs_norm), applied before forward
    obs_stats: bool = False  # also return each member's observation count, sum and sum of squares
    # (d,) a period of info['position'] the run found in its own recorded rows after its start (the shaped guide's
    # late check, guides/shaped_data.py); None: the env's own (rollout/periodic.period_of: declared or detected)
    position_period: np.ndarray | None = None
    during: str = ""  # what the rollout is part of, for its errors ("": its generation; :meth:`where`)

    def where(self) -> str:
        """Where in the run this rollout is, as its error lines name it: generations counted from 1, as the
        progress line's ``gen N/T`` and the checkpoints' ``gen_N`` count them (only metrics.csv's column
        counts from 0: the row ``generation`` 1 is "generation 2" here)."""
        return self.during or f"generation {self.generation + 1}"

    def recorded(self) -> np.ndarray:
        """Mask ``(m,)`` of the members whose transitions are kept."""
        m = self.params.shape[0]
        if isinstance(self.record, (bool, np.bool_)):
            return np.full(m, bool(self.record))
        mask = np.asarray(self.record, dtype=bool).reshape(-1)
        if mask.shape != (m,):
            raise ValueError(f"record mask has {mask.shape[0]} entries for {m} members")
        return mask


@dataclass
class RolloutResult:
    members: np.ndarray  # (m,)
    returns: np.ndarray  # (m, E) float64, cumulative reward per episode
    lengths: np.ndarray  # (m, E) int64, steps per episode
    cpu_time_s: float  # CPU seconds this task used in its process
    # the recorded members' steps as one block (None: nothing recorded); one object to pickle, not one
    # per member (``transitions`` unpacks it into per-member views)
    packed: PackedTransitions | None = None
    # RolloutTask.obs_stats: per member, the raw observations its policy saw (alive steps, float32 values
    # summed in float64): count (m,), sum (m, obs), sum of squares (m, obs); the master merges them in
    # member order, so the statistics do not depend on how members were split into tasks
    obs_stats: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def transitions(self) -> list[Transitions]:
        """One :class:`Transitions` per recorded member (views of :attr:`packed`; ``[]`` without)."""
        return [] if self.packed is None else self.packed.unpack()

    @transitions.setter
    def transitions(self, trs: list[Transitions]) -> None:
        self.packed = pack(list(trs)) if len(trs) else None


def mean_returns(results: list[RolloutResult]) -> np.ndarray:
    """Each member's mean return, ``(m,)`` in member order, from results whose returns are ``(m_i, E_i)``
    (a guide's extra members may run more episodes than the population)."""
    return np.concatenate([np.asarray(r.returns).mean(axis=1) for r in results])


def population_tasks(env_id: str, env_kwargs: dict, spec: MLPSpec, params: np.ndarray, seeds: np.ndarray,
                     workers: int, generation: int = 0, record: bool | np.ndarray = False,
                     max_steps: int | None = None, expert: bool = False, obs_norm: ObsNorm | None = None,
                     obs_stats: bool = False, position_period: np.ndarray | None = None) -> list[RolloutTask]:
    """A population ``params`` ``(P, n)`` on its episode seeds ``(P, E)``, as at most ``workers`` tasks of
    consecutive members (training rollouts); ``record``: every member, or a mask ``(P,)``; ``obs_norm``:
    the members' input normalization; ``obs_stats``: return their observations' sums; ``position_period``:
    ``RolloutTask.position_period``."""
    members = np.arange(params.shape[0])
    rec = record if isinstance(record, (bool, np.bool_)) else np.asarray(record, dtype=bool).reshape(-1)
    return [RolloutTask(env_id, env_kwargs, spec, params[idx], members[idx], seeds[idx], generation=generation,
                        record=rec if isinstance(rec, (bool, np.bool_)) else rec[idx], max_steps=max_steps,
                        expert=expert, obs_norm=obs_norm, obs_stats=obs_stats, position_period=position_period)
            for idx in np.array_split(members, max(1, min(len(members), workers)))]


def policy_episode_tasks(env_id: str, env_kwargs: dict, spec: MLPSpec, theta: np.ndarray,
                         seeds: np.ndarray, workers: int, generation: int = 0,
                         max_steps: int | None = None, rowwise: bool = False,
                         obs_norm: ObsNorm | None = None, during: str = "") -> list[RolloutTask]:
    """One policy ``theta`` ``(n,)`` on episode seeds ``(E,)``, split into at most ``workers`` tasks
    (test and evaluation episodes; each task is "member 0" of its own chunk of seeds); ``rowwise``:
    ``evaluate``'s episodes, whose actions equal ``load_policy(...).predict``'s bit for bit; ``obs_norm``:
    the policy's input normalization; ``during``: ``RolloutTask.during`` (episodes outside a generation)."""
    seeds = np.asarray(seeds).reshape(1, -1)  # (1, E)
    E = seeds.shape[1]
    return [RolloutTask(env_id, env_kwargs, spec, theta[None], np.zeros(1, int), seeds[:, c],
                        generation=generation, max_steps=max_steps, rowwise=rowwise, obs_norm=obs_norm,
                        during=during)
            for c in np.array_split(np.arange(E), max(1, min(E, workers)))]


def _policy_input(task: RolloutTask, obs: np.ndarray) -> np.ndarray:
    """The observations ``(B, obs)`` as the policies take them (``task.obs_norm`` applied, if any)."""
    return obs if task.obs_norm is None else task.obs_norm.apply(obs)


def _finish(task, returns, lengths, rec, sums=None) -> RolloutResult:
    """A loop's result of ``task``: its episodes' ``returns`` and ``lengths`` ``(m*E,)``, the recorder's
    block (``rec``, or None) and the observation sums (``sums``, or None)."""
    m, E = task.seeds.shape
    return RolloutResult(obs_stats=None if sums is None else sums.per_member(m, E),
        members=np.asarray(task.members),
        returns=returns.reshape(m, E),  # (m*E,) -> (m, E)
        lengths=lengths.reshape(m, E),
        cpu_time_s=0.0,
        packed=rec.build() if rec is not None else None,
    )
