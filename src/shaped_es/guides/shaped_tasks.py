"""Worker side of the paper's Algorithm 1 on a cluster (``shaping.placement = workers``): roll out and
write trajectories; label and behaviour-clone.

Both functions take one picklable task and return small summaries; trajectories travel through the
trajectory store (the paper's NFS), never back to the master. Each worker process also keeps the
transitions it wrote or read in a small in-memory cache keyed by (store, generation, member), so a
task that lands where its members' data already are reads nothing; a cache miss (another worker, or a
restart) reads the store. Both give the same arrays, hence the same ``theta*``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from shaped_es.data import Transitions
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutResult, RolloutTask, run_task
from shaped_es.shaping.cloning import CloneResult, CloningConfig, clone_sampled
from shaped_es.shaping.member_rows import MemberRows
from shaped_es.shaping.frames import frame_dim
from shaped_es.shaping.inverse_dynamics import InverseDynamics, InverseDynamicsConfig, query_inputs
from shaped_es.shaping.trajectories import TrajectoryStoreError, read_members, write_shard

# (traj_root, generation, member) -> transitions; per worker process, bounded by _CACHE_GENERATIONS
_CACHE: dict[tuple[str, int, int], Transitions] = {}
_CACHE_GENERATIONS = 8


def _remember(root: str, trs: list[Transitions]) -> None:
    for tr in trs:
        _CACHE[(root, tr.generation, tr.member)] = tr
    newest = max((k[1] for k in _CACHE), default=0)
    for k in [k for k in _CACHE if k[1] <= newest - _CACHE_GENERATIONS]:
        del _CACHE[k]


def rollout_and_store(task: RolloutTask, traj_root: str) -> RolloutResult:
    """Evaluate the chunk and write its recorded transitions as one shard (Alg. 1, l. 4-6); returns
    only (``task.record``: the members the guide records)."""
    res = run_task(task)
    if res.packed is not None:
        t1 = time.perf_counter()
        write_shard(traj_root, res.packed)
        res.store_time_s = time.perf_counter() - t1
        _remember(traj_root, res.transitions)  # per-member views of the block
    res.packed = None
    return res


def member_data(traj_root: str, members, generations) -> dict[int, list[Transitions]]:
    """``D_i`` of each member (oldest first) from this process's cache, else from the store."""
    members = [int(m) for m in members]
    gens = sorted(set(int(g) for g in generations))
    found = {(g, m): _CACHE[(traj_root, g, m)] for g in gens for m in members if (traj_root, g, m) in _CACHE}
    missing = sorted({g for g in gens for m in members if (g, m) not in found})
    fresh = [tr for trs in (read_members(traj_root, members, missing) if missing else {}).values() for tr in trs]
    found |= {(tr.generation, tr.member): tr for tr in fresh}
    lost = sorted({g for g in gens for m in members if (g, m) not in found})
    if lost:  # every generation's rollouts write every member's shard: these were lost
        raise TrajectoryStoreError(f"trajectory generation(s) {lost} missing from {traj_root} (deleted?); "
                                   f"the shaped method needs them to continue")
    _remember(traj_root, fresh)
    return {m: [found[(g, m)] for g in gens] for m in members}


def states_and_queries(hist: list[Transitions], frame: str, obs_dim: int, pos_dim: int,
                       scale: str = "raw", mix: float = 1.0, step_change: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """One member's ``D_i`` as states ``(T, obs)`` and M_phi's queries ``(T, d)`` (before any clip; with
    ``step_change`` the last step after them, ``(T, d + d)``: ``mphi_inputs.query_inputs``)."""
    if not hist:
        return np.zeros((0, obs_dim), np.float32), np.zeros((0, frame_dim(frame, pos_dim) + pos_dim * step_change),
                                                            np.float32)
    s = np.concatenate([h.state for h in hist])
    q = np.concatenate([query_inputs(h, frame, scale, mix, step_change) for h in hist])
    return s, q.astype(np.float32)


def states_and_expert(hist: list[Transitions], obs_dim: int, act_dim: int) -> tuple[np.ndarray, np.ndarray]:
    """One member's ``D_i`` as states ``(T, obs)`` and the env controller's actions ``(T, act)``."""
    if not hist:
        return np.zeros((0, obs_dim), np.float32), np.zeros((0, act_dim), np.float32)
    if any(h.expert is None for h in hist):
        raise TrajectoryStoreError("trajectory shards lack the controller's actions (column 'expert'): "
                                   "they were written by a run without shaping.labels=controller")
    return np.concatenate([h.state for h in hist]), np.concatenate([h.expert for h in hist])


def labeller(mphi: InverseDynamics, max_displacement: float | None):
    """``(states, raw queries) -> a_hat``; queries clipped per row to ``max_displacement`` first."""
    def label(states: np.ndarray, queries: np.ndarray) -> np.ndarray:
        return mphi.ask(states, queries, max_displacement)
    return label


@dataclass
class CloneTask:
    spec: MLPSpec
    theta: np.ndarray  # (m, n) float32, the members as evaluated (cloning starts here)
    members: np.ndarray  # (m,) population slots
    seeds: np.ndarray  # (m,) per-member minibatch seeds (chunking-independent)
    generations: list[int]  # generations whose data form D_i (DAgger-style aggregation)
    traj_root: str
    mphi_state: dict[str, np.ndarray] | None  # M_phi network + normalizer (no training state); mphi labels
    mphi_config: InverseDynamicsConfig
    cloning: CloningConfig
    max_displacement: float | None = None  # clip |w_t - p_t| (None: raw, as the paper)
    labels: str = "mphi"  # the label source: mphi (M_phi's labels) or controller (recorded in the shards)


@dataclass
class CloneOutput:
    members: np.ndarray  # (m,)
    result: CloneResult  # theta_star (m, n), losses, samples, label_std
    cpu_time_s: float


def label_and_clone(task: CloneTask) -> CloneOutput:
    """Label each member's aggregated data D_i (with M_phi, or the controller's recorded actions) and
    clone from theta_i (Alg. 1, l. 7-10)."""
    t_cpu = time.process_time()
    data = member_data(task.traj_root, task.members, task.generations)
    if task.labels == "controller":
        sq = [states_and_expert(data[int(m)], task.spec.obs_dim, task.spec.act_dim) for m in task.members]
        label = lambda states, expert: expert  # noqa: E731 - the recorded actions are the labels
    else:
        mphi = InverseDynamics.from_state_dict(task.mphi_state, task.mphi_config)
        sq = [states_and_queries(data[int(m)], task.mphi_config.frame, mphi.obs_dim, mphi.pos_dim,
                                 task.mphi_config.query_scale, task.mphi_config.query_mix, mphi.step_change)
              for m in task.members]
        label = labeller(mphi, task.max_displacement)
    rows = MemberRows.from_lists([s for s, _ in sq], [q for _, q in sq])
    res = clone_sampled(task.spec, task.theta, rows, label, task.cloning, task.seeds)
    return CloneOutput(members=np.asarray(task.members), result=res, cpu_time_s=time.process_time() - t_cpu)
