"""Worker side of the paper's Algorithm 1: roll out and write trajectories; label and behaviour-clone.

Both functions take one picklable task and return small summaries: trajectories travel through the
trajectory store (the paper's NFS), never back to the master.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutResult, RolloutTask, run_task
from shaped_es.shaping.cloning import CloningConfig, clone_population
from shaped_es.shaping.inverse_dynamics import InverseDynamics, InverseDynamicsConfig, query_displacement
from shaped_es.shaping.trajectories import read_member_history, write_shard


def rollout_and_store(task: RolloutTask, traj_root: str) -> RolloutResult:
    """Evaluate the chunk, write one Parquet shard per member, return returns only (Algorithm 1, l. 4-6)."""
    task.record = True
    res = run_task(task)
    for tr in res.transitions:
        write_shard(traj_root, tr)
    res.transitions = []
    return res


@dataclass
class CloneTask:
    spec: MLPSpec
    theta: np.ndarray  # (m, n) float32, the members as evaluated (cloning starts here)
    members: np.ndarray  # (m,) population slots
    seeds: np.ndarray  # (m,) per-member minibatch seeds (chunking-independent)
    generations: list[int]  # generations whose shards form D_i (DAgger-style aggregation)
    traj_root: str
    mphi_state: dict[str, np.ndarray]  # M_phi network + normalizer (no training state)
    mphi_config: InverseDynamicsConfig
    cloning: CloningConfig
    max_displacement: float | None = None  # clip |w_t - p_t| (None: raw, as the paper)


@dataclass
class CloneOutput:
    members: np.ndarray  # (m,)
    theta_star: np.ndarray  # (m, n) float32
    loss_before: np.ndarray  # (m,) MSE to the labels at theta_i
    loss_after: np.ndarray  # (m,) MSE at theta*_i
    samples: np.ndarray  # (m,) size of D_i used
    cpu_time_s: float
    label_std: float = 0.0  # spread of the labels (a collapsed M_phi gives ~0)


def clip_norm(d: np.ndarray, max_norm: float | None) -> np.ndarray:
    """Scale rows of ``d`` ``(T, k)`` down to at most ``max_norm`` in Euclidean norm."""
    if max_norm is None:
        return d
    n = np.linalg.norm(d, axis=-1, keepdims=True)  # (T, 1)
    return d * np.minimum(1.0, max_norm / np.maximum(n, 1e-12))


def label_and_clone(task: CloneTask) -> CloneOutput:
    """Label each member's aggregated data D_i with M_phi and clone from theta_i (Algorithm 1, l. 7-10)."""
    t_cpu = time.process_time()
    mphi = InverseDynamics.from_state_dict(task.mphi_state, task.mphi_config)
    states, labels = [], []
    for m in task.members:
        hist = read_member_history(task.traj_root, int(m), task.generations)
        s = [h.state for h in hist]
        frame = task.mphi_config.frame
        a = [mphi.label(h.state, clip_norm(query_displacement(h, frame), task.max_displacement)) for h in hist]
        states.append(np.concatenate(s) if s else np.zeros((0, task.spec.obs_dim), np.float32))
        labels.append(np.concatenate(a) if a else np.zeros((0, task.spec.act_dim), np.float32))
    res = clone_population(task.spec, task.theta, states, labels, config=task.cloning, seeds=task.seeds)
    all_labels = np.concatenate(labels) if labels else np.zeros((0, task.spec.act_dim))
    return CloneOutput(
        members=np.asarray(task.members), theta_star=res.theta_star, loss_before=res.loss_before,
        loss_after=res.loss_after, samples=res.samples, cpu_time_s=time.process_time() - t_cpu,
        label_std=float(all_labels.std(axis=0).mean()) if len(all_labels) else 0.0,
    )
