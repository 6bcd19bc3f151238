"""The hand-written M_phi network: gradients equal torch autograd, Adam equals torch.optim.Adam."""

from __future__ import annotations

import numpy as np
import torch

from shaped_es.shaping.lean_mlp import FlatAdam, LeanMLP


def _torch_twin(net: LeanMLP) -> list[torch.Tensor]:
    return [torch.tensor(a, dtype=torch.float64, requires_grad=True) for a in (*net.W, *net.b)]


def _torch_forward(params, x, n_layers):
    h = x
    for li in range(n_layers):
        a = h @ params[li] + params[n_layers + li]
        h = torch.tanh(a) if li == n_layers - 1 else torch.relu(a)
    return h


def test_forward_and_gradient_match_autograd():
    rng = np.random.default_rng(0)
    net = LeanMLP((7, 5, 4, 3), rng)
    x = rng.standard_normal((11, 7)).astype(np.float32)
    y = np.tanh(rng.standard_normal((11, 3))).astype(np.float32)
    params = _torch_twin(net)
    out = _torch_forward(params, torch.tensor(x, dtype=torch.float64), 3)
    np.testing.assert_allclose(net.forward(x), out.detach().numpy(), rtol=1e-5, atol=1e-6)
    loss = torch.mean((out - torch.tensor(y, dtype=torch.float64)) ** 2)
    loss.backward()
    got = net.mse_backward(x, y)
    assert abs(got - loss.item()) < 1e-6
    for mine, ref in zip((*net.gW, *net.gb), params):
        np.testing.assert_allclose(mine, ref.grad.numpy(), rtol=1e-4, atol=1e-6)
    assert np.abs(net.grad).sum() > 0  # the views really fill the flat buffer


def test_adam_matches_torch_over_many_steps():
    rng = np.random.default_rng(1)
    x0 = rng.standard_normal(50).astype(np.float32)
    grads = rng.standard_normal((30, 50)).astype(np.float32)
    mine, opt = x0.copy(), FlatAdam(50, lr=1e-2)
    ref = torch.tensor(x0, requires_grad=True)
    topt = torch.optim.Adam([ref], lr=1e-2)
    for g in grads:
        opt.step(mine, g)
        ref.grad = torch.tensor(g)
        topt.step()
    np.testing.assert_allclose(mine, ref.detach().numpy(), rtol=1e-5, atol=1e-6)


def test_training_fits_a_small_regression():
    rng = np.random.default_rng(2)
    net = LeanMLP((3, 16, 1), rng)
    opt = FlatAdam(net.num_params, lr=1e-2)
    x = rng.uniform(-1, 1, (256, 3)).astype(np.float32)
    y = np.tanh(x @ np.array([[0.5], [-0.3], [0.2]], np.float32))
    first = net.mse_backward(x, y)
    for _ in range(300):
        last = net.mse_backward(x, y)
        opt.step(net.flat, net.grad)
    assert last < 0.05 * first
