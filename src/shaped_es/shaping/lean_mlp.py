"""A small ReLU MLP (tanh output) with a hand-written backward pass and Adam, over one flat float32 buffer.

Written by hand because it is faster for ``M_phi``'s size (in ~40 -> 20 -> 20 -> act, minibatch 64):
one Adam step costs ~50-80 us here against ~260 us through ``torch.nn`` + ``torch.optim.Adam(fused)``
(per-op dispatch dominates at this size; measured on this project's 2-core machine), and the rollout
workers never need torch for it. The maths is the textbook one; ``tests/shaping/test_lean_mlp.py``
checks gradients against torch autograd and Adam against ``torch.optim.Adam``.

Layout of the flat parameter vector: for each layer ``W_l`` ``(in_l, out_l)`` row-major, then ``b_l``.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


class LeanMLP:
    """``sizes = (in, h_1, ..., out)``: ReLU on hidden layers, tanh on the output."""

    def __init__(self, sizes: Sequence[int], rng: np.random.Generator):
        self.sizes = tuple(int(s) for s in sizes)
        shapes = list(zip(self.sizes[:-1], self.sizes[1:]))
        self.num_params = sum(i * o + o for i, o in shapes)
        self.flat = np.zeros(self.num_params, np.float32)  # (n,) the parameters
        self.grad = np.zeros(self.num_params, np.float32)  # (n,) last gradient, same layout
        self.W, self.b, self.gW, self.gb = [], [], [], []
        k = 0
        for i, o in shapes:  # views into the flat buffers
            self.W.append(self.flat[k : k + i * o].reshape(i, o))
            self.gW.append(self.grad[k : k + i * o].reshape(i, o))
            k += i * o
            self.b.append(self.flat[k : k + o])
            self.gb.append(self.grad[k : k + o])
            k += o
        for W, b in zip(self.W, self.b):  # PyTorch's nn.Linear default: U(-1/sqrt(in), 1/sqrt(in))
            bound = 1.0 / np.sqrt(W.shape[0])
            W[...] = rng.uniform(-bound, bound, W.shape)
            b[...] = rng.uniform(-bound, bound, b.shape)

    def forward(self, x: np.ndarray) -> np.ndarray:
        """``(N, in)`` -> ``(N, out)`` in ``[-1, 1]``."""
        h = x
        last = len(self.W) - 1
        for li, (W, b) in enumerate(zip(self.W, self.b)):
            a = h @ W  # (N, out_l)
            a += b
            h = np.tanh(a, out=a) if li == last else np.maximum(a, 0.0, out=a)
        return h

    def mse_backward(self, x: np.ndarray, y: np.ndarray) -> float:
        """Fill :attr:`grad` with d/dtheta of ``mean((f(x) - y)^2)`` over all ``N x out`` entries; returns
        the loss. ``x`` ``(N, in)``, ``y`` ``(N, out)``."""
        hs = [x]  # layer inputs
        last = len(self.W) - 1
        for li, (W, b) in enumerate(zip(self.W, self.b)):
            a = hs[-1] @ W + b  # (N, out_l)
            hs.append(np.tanh(a) if li == last else np.maximum(a, 0.0))
        out = hs[-1]
        diff = out - y  # (N, out)
        loss = float(np.mean(diff * diff))
        g = diff * ((2.0 / diff.size) * (1.0 - out * out))  # dL/da of the tanh layer
        for li in range(last, -1, -1):
            np.matmul(hs[li].T, g, out=self.gW[li])  # (in_l, out_l)
            np.sum(g, axis=0, out=self.gb[li])
            if li:
                g = (g @ self.W[li].T) * (hs[li] > 0)  # through the ReLU of layer li-1
        return loss


ADAM_BETAS, ADAM_EPS = (0.9, 0.999), 1e-8  # PyTorch's defaults


class FlatAdam:
    """Adam (Kingma & Ba; PyTorch's defaults and bias correction) on one flat float32 buffer."""

    def __init__(self, size, lr: float, betas=ADAM_BETAS, eps: float = ADAM_EPS):
        self.lr, (self.b1, self.b2), self.eps = lr, betas, eps
        self.m = np.zeros(size, np.float32)  # (n,) or (P, n): first moment
        self.v = np.zeros(size, np.float32)  # second moment
        self._tmp = np.zeros(size, np.float32)  # scratch: one step allocates nothing
        self.t = 0

    def step(self, params: np.ndarray, grad: np.ndarray) -> None:
        """One Adam step in place, as ``torch.optim.Adam``: ``p -= lr/bc1 * m / (sqrt(v)/sqrt(bc2) + eps)``."""
        self.t += 1
        m, v, tmp = self.m, self.v, self._tmp
        m *= self.b1
        np.multiply(grad, 1.0 - self.b1, out=tmp)
        m += tmp  # m = b1 m + (1 - b1) g
        v *= self.b2
        np.multiply(grad, grad, out=tmp)
        tmp *= 1.0 - self.b2
        v += tmp  # v = b2 v + (1 - b2) g^2
        np.sqrt(v, out=tmp)
        tmp /= np.sqrt(1.0 - self.b2**self.t)
        tmp += self.eps  # denominator
        np.divide(m, tmp, out=tmp)
        tmp *= self.lr / (1.0 - self.b1**self.t)
        params -= tmp
