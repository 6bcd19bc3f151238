"""Behaviour cloning's gradient steps for a chunk of members, on rows already drawn and labelled: the task
the master hands to idle workers (torch-free, so those workers never import torch)."""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from shaped_es.policies import MLPSpec
from shaped_es.shaping import kernels
from shaped_es.shaping.lean_mlp import ADAM_BETAS, ADAM_EPS
from shaped_es.shaping.param_noise import normals
from shaped_es.shaping.population_mlp import PopulationMLP, make_optimizer
from shaped_es.shaping.shared_rows import RowsRef


@dataclass
class FitTask:
    """Gradient steps of a chunk of members on rows already drawn and labelled (picklable)."""

    spec: MLPSpec
    theta: np.ndarray  # (P, n) float32
    S: np.ndarray | None  # (draws, P, B, obs) float32: minibatch k is S[k] (None: in ``rows``)
    A: np.ndarray | None  # (draws, P, B, act) float32 labels
    has: np.ndarray  # (P,) bool: members with data
    steps: int
    optimizer: str
    lr: float
    k_eval: int  # the first k_eval minibatches are the eval rows
    rows: RowsRef | None = None  # S and A of the whole population in shared memory, instead of S, A
    members: tuple[int, int] = (0, 0)  # with ``rows``: this chunk's members [start, stop) in them
    noise: float = 0.0  # > 0: each step's gradient is taken at theta + noise * z (shaping/param_noise.py)
    noise_seeds: np.ndarray | None = None  # (P,) uint64: each member's z stream (with noise > 0)

    def arrays(self) -> tuple[np.ndarray, np.ndarray]:
        """``S``, ``A`` of this chunk's members (views of shared memory when ``rows`` is set)."""
        if self.rows is None:
            return self.S, self.A
        d, (a, b) = self.rows.open(), self.members
        return d["S"][:, a:b], d["A"][:, a:b]  # (draws, m, B, obs), (draws, m, B, act)


def fit_rows(task: FitTask):
    """``(theta_star (P, n), mse_before (P,), mse_after (P,), own actions before / after (P, kB, act),
    CPU seconds)`` of ``task.steps`` Adam/SGD steps, minibatch ``k`` = rows ``S[k]``, one NumPy
    computation for all (:class:`PopulationMLP`; the same steps as torch's, to float tolerance), or one
    compiled call (``kernels.fit_population``, the default; the same steps to float tolerance). With
    ``task.noise`` > 0 member ``p``'s step ``k`` takes its gradient at ``theta_p + noise * z`` (``z`` =
    ``param_noise.normals(noise_seeds[p], k, n)``) and applies it to ``theta_p``: the fit of the loss smoothed
    by that parameter noise."""
    cpu0 = time.process_time()
    has, k_eval = np.asarray(task.has), task.k_eval
    S, A = task.arrays()
    net = PopulationMLP(task.spec, task.theta)
    P, B = net.flat.shape[0], S.shape[2]
    weight = has.astype(np.float32)  # (P,) members without data get no gradient
    n = net.flat.shape[1]
    noisy = task.noise > 0
    if noisy and (task.noise_seeds is None or np.shape(task.noise_seeds) != (P,)):
        raise ValueError(f"cloning noise {task.noise} needs one noise seed per member ({P}), got {task.noise_seeds!r}")
    seeds = np.asarray(task.noise_seeds if noisy else np.zeros(P), np.uint64)  # (P,)
    s_eval = S[:k_eval].transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)  # (k, P, B, obs) -> (P, kB, obs)
    a_eval = A[:k_eval].transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)  # (P, kB, act)
    acts: list[np.ndarray] = []  # the members' own actions on the eval rows, before and after

    def eval_mse() -> np.ndarray:
        pred = net.forward(s_eval)  # (P, kB, act)
        acts.append(pred)
        mse = ((pred - a_eval) ** 2).mean((1, 2), dtype=np.float64)  # (P,)
        return np.where(has, mse, np.nan)

    before = eval_mse()
    if task.steps > 0 and has.any() and kernels.ENABLED:  # all the steps in one compiled call
        if task.optimizer not in ("adam", "sgd"):
            make_optimizer(task.optimizer, net.flat.shape, task.lr)  # its one-line error
        kernels.fit_population(net.flat, S[: task.steps], A[: task.steps], weight, task.optimizer == "adam",
                               float(task.lr), ADAM_BETAS[0], ADAM_BETAS[1], ADAM_EPS,
                               np.array(task.spec.sizes, np.int64), float(task.noise), seeds)
    elif task.steps > 0 and has.any():
        opt = make_optimizer(task.optimizer, net.flat.shape, task.lr)
        for k in range(task.steps):
            if noisy:  # the gradient at theta + noise z_k, applied to theta
                kept = net.flat.copy()  # (P, n)
                net.flat += np.float32(task.noise) * np.stack([normals(int(s), k, n) for s in seeds])  # (P, n)
            net.mse_backward(S[k], A[k], weight)  # sum_i L_i(theta_i), Eq. L(theta) per member
            if noisy:
                net.flat[...] = kept
            opt.step(net.flat, net.grad)
    after = eval_mse()
    return net.flat, before, after, acts[0], acts[1], time.process_time() - cpu0
