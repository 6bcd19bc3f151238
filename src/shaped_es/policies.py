"""MLP policies whose parameters are one flat float32 vector, evaluated for a whole population at once.

Layout of the flat vector ``theta`` (length ``n = MLPSpec.num_params``): for each layer ``l`` in order,
the weight matrix ``W_l`` of shape ``(in_l, out_l)`` in row-major order, then its bias ``b_l`` ``(out_l,)``.
Hidden layers use ``tanh``; the output layer uses ``tanh`` too, so actions lie in ``[-1, 1]`` (envs
rescale to their own bounds). The same layout is used by the NumPy forward (rollouts: no torch in the
hot loop) and by the torch forward (behaviour cloning in ``shaping/``), so a vector means the same
policy in both.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class MLPSpec:
    """Architecture of a policy: ``obs_dim -> hidden... -> act_dim``."""

    obs_dim: int
    act_dim: int
    hidden: tuple[int, ...] = field(default=(32, 32))

    @property
    def sizes(self) -> tuple[int, ...]:
        return (self.obs_dim, *self.hidden, self.act_dim)

    @property
    def layer_shapes(self) -> list[tuple[int, int]]:
        s = self.sizes
        return [(s[i], s[i + 1]) for i in range(len(s) - 1)]

    @property
    def num_params(self) -> int:
        return sum(i * o + o for i, o in self.layer_shapes)

    def slices(self) -> list[tuple[slice, slice]]:
        """(weight slice, bias slice) into the flat vector, per layer."""
        out, k = [], 0
        for i, o in self.layer_shapes:
            w = slice(k, k + i * o)
            k += i * o
            b = slice(k, k + o)
            k += o
            out.append((w, b))
        return out

    def init(self, seed: int) -> np.ndarray:
        """Glorot-uniform weights, zero biases; the last layer scaled by 0.1 (small initial actions)."""
        rng = np.random.default_rng(seed)
        theta = np.zeros(self.num_params, dtype=np.float32)
        shapes = self.layer_shapes
        for li, ((i, o), (ws, _)) in enumerate(zip(shapes, self.slices())):
            lim = np.sqrt(6.0 / (i + o))
            if li == len(shapes) - 1:
                lim *= 0.1
            theta[ws] = rng.uniform(-lim, lim, size=i * o).astype(np.float32)
        return theta


def forward(spec: MLPSpec, params: np.ndarray, obs: np.ndarray, rowwise: bool = False) -> np.ndarray:
    """Batched forward over a population.

    params: ``(P, n)``; obs: ``(P, B, obs_dim)`` -> actions ``(P, B, act_dim)`` in ``[-1, 1]``.

    ``rowwise``: each row's action depends only on its own parameters and observation, bit for bit,
    whatever else is in the batch: every row is its own vector-matrix product. One BLAS matrix product
    over the B rows (the default: up to 1.8x faster, what the training rollouts use) rounds a row
    differently depending on how many rows it holds, so a policy evaluated on a chunk of episodes would
    act differently, in the last bits, from the same policy on one observation: enough to change an
    episode of a chaotic task. ``evaluate`` and ``load_policy(...).predict`` use ``rowwise``, so a plain
    gymnasium loop returns what ``evaluate`` reports.
    """
    params = np.ascontiguousarray(params, dtype=np.float32)  # contiguous: the same BLAS path every call
    h = np.ascontiguousarray(obs, dtype=np.float32)
    P = params.shape[0]
    for (i, o), (ws, bs) in zip(spec.layer_shapes, spec.slices()):
        b = params[:, bs][:, None, :]  # (P, 1, out)
        if rowwise:
            W = params[:, ws].reshape(P, 1, i, o)  # (P, 1, in, out), shared by the B rows
            h = np.tanh(np.matmul(h[..., None, :], W)[..., 0, :] + b)  # (P, B, 1, in) @ W -> (P, B, out)
        else:
            W = params[:, ws].reshape(P, i, o)  # (P, in, out)
            h = np.tanh(np.matmul(h, W) + b)  # (P, B, in) @ W -> (P, B, out)
    return h


def forward_torch(spec: MLPSpec, params, obs):
    """Torch twin of :func:`forward` (differentiable in ``params``).

    params: ``(P, n)`` tensor; obs: ``(P, B, obs_dim)`` tensor -> ``(P, B, act_dim)``.
    """
    import torch

    h = obs
    P = params.shape[0]
    for (i, o), (ws, bs) in zip(spec.layer_shapes, spec.slices()):
        W = params[:, ws].reshape(P, i, o)  # (P, in, out)
        b = params[:, bs].unsqueeze(1)  # (P, 1, out)
        h = torch.tanh(torch.bmm(h, W) + b)  # (P, B, out)
    return h


# -- observation normalization (ARS V2, Mania et al. 2018; OpenAI-ES; SB3's VecNormalize) ------------------
OBS_CLIP = 5.0  # normalized observations are clipped to [-OBS_CLIP, OBS_CLIP] (ARS, OpenAI-ES)
OBS_EPS = 1e-8  # added to the variance: a constant observation stays finite (VecNormalize's epsilon)


@dataclass(frozen=True)
class ObsNorm:
    """The policy's input pipeline: ``obs' = clip((obs - mean) / std, -OBS_CLIP, OBS_CLIP)`` in float32,
    applied before :func:`forward` (outside the flat parameters, the ARS way: a change of statistics does
    not change what a parameter vector means). Elementwise, so an observation's normalized value does not
    depend on the batch it is in: rollouts and ``load_policy(...).predict`` agree bit for bit."""

    mean: np.ndarray  # (obs_dim,) float32
    std: np.ndarray  # (obs_dim,) float32, sqrt(var + OBS_EPS)

    def apply(self, obs: np.ndarray) -> np.ndarray:
        """``(..., obs_dim)`` -> normalized float32 ``(..., obs_dim)``."""
        x = np.asarray(obs, dtype=np.float32)
        return np.clip((x - self.mean) / self.std, np.float32(-OBS_CLIP), np.float32(OBS_CLIP))


@dataclass
class ObsStats:
    """Running mean and variance of observations in float64 (count, mean, ``M2`` = sum of squared
    deviations; Chan et al. 1979's parallel merge). Before any observation: mean 0, variance 1."""

    count: float
    mean: np.ndarray  # (obs_dim,) float64
    m2: np.ndarray  # (obs_dim,) float64

    @classmethod
    def empty(cls, obs_dim: int) -> ObsStats:
        return cls(0.0, np.zeros(obs_dim), np.zeros(obs_dim))

    @classmethod
    def from_sums(cls, count: float, total: np.ndarray, squares: np.ndarray) -> ObsStats:
        """A batch's statistics from its count, sum ``(d,)`` and sum of squares ``(d,)``."""
        if count <= 0:
            return cls.empty(np.shape(total)[0])
        mean = np.asarray(total, np.float64) / count
        m2 = np.maximum(np.asarray(squares, np.float64) - total * mean, 0.0)  # sum x^2 - n mean^2
        return cls(float(count), mean, m2)

    def merge(self, other: ObsStats) -> ObsStats:
        """Both batches as one (Chan et al.: ``delta = mean_b - mean_a``, ``M2 = M2_a + M2_b + delta^2
        n_a n_b / n``)."""
        n = self.count + other.count
        if other.count == 0:
            return ObsStats(self.count, self.mean.copy(), self.m2.copy())
        if self.count == 0:
            return ObsStats(other.count, other.mean.copy(), other.m2.copy())
        delta = other.mean - self.mean  # (d,)
        mean = self.mean + delta * (other.count / n)
        m2 = self.m2 + other.m2 + delta * delta * (self.count * other.count / n)
        return ObsStats(n, mean, m2)

    @property
    def var(self) -> np.ndarray:
        return self.m2 / self.count if self.count > 0 else np.ones_like(self.mean)

    def norm(self) -> ObsNorm:
        """The normalizer these statistics give (float32, as the policy applies it)."""
        return ObsNorm(self.mean.astype(np.float32), np.sqrt(self.var + OBS_EPS).astype(np.float32))
