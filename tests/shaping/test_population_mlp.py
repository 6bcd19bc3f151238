"""The hand-written population kernel of behaviour cloning: forward = policies.forward, gradients =
torch autograd, and whole fits = the same steps taken by torch autograd + torch.optim."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from shaped_es.policies import MLPSpec, forward, forward_torch
from shaped_es.shaping.population_mlp import PopulationMLP, make_optimizer

SPEC = MLPSpec(7, 3, (6, 5))


def _population(P=4, seed=0):
    rng = np.random.default_rng(seed)
    theta = np.stack([SPEC.init(s) for s in range(P)]) + rng.normal(0, 0.3, (P, SPEC.num_params))
    x = rng.standard_normal((P, 9, SPEC.obs_dim)).astype(np.float32)
    y = np.tanh(rng.standard_normal((P, 9, SPEC.act_dim))).astype(np.float32)
    return theta.astype(np.float32), x, y


def test_forward_is_the_policy_forward():
    theta, x, _ = _population()
    np.testing.assert_allclose(PopulationMLP(SPEC, theta).forward(x), forward(SPEC, theta, x), atol=1e-6)


def test_gradient_matches_autograd_per_member_weighted():
    theta, x, y = _population()
    w = np.array([1.0, 0.0, 0.5, 2.0], np.float32)
    net = PopulationMLP(SPEC, theta)
    net.mse_backward(x, y, w)
    p = torch.tensor(theta, dtype=torch.float64, requires_grad=True)
    out = forward_torch(SPEC, p, torch.tensor(x, dtype=torch.float64))
    per = ((out - torch.tensor(y, dtype=torch.float64)) ** 2).mean((1, 2))  # (P,)
    (per * torch.tensor(w, dtype=torch.float64)).sum().backward()
    np.testing.assert_allclose(net.grad, p.grad.numpy(), rtol=1e-4, atol=1e-6)
    assert np.all(net.grad[1] == 0) and np.abs(net.grad[0]).sum() > 0  # weight 0: no gradient
    np.testing.assert_array_equal(net.flat, theta)  # a copy: the caller's theta is not touched


@pytest.mark.parametrize("name", ["adam", "sgd"])
def test_steps_match_torch_optimizer(name):
    theta, x, y = _population(seed=3)
    net, opt = PopulationMLP(SPEC, theta), make_optimizer(name, theta.shape, 1e-2)
    p = torch.tensor(theta, requires_grad=True)
    topt = (torch.optim.Adam if name == "adam" else torch.optim.SGD)([p], lr=1e-2)
    for k in range(15):
        xs, ys = np.roll(x, k, axis=1), np.roll(y, k, axis=1)
        net.mse_backward(xs, ys, np.ones(4, np.float32))
        opt.step(net.flat, net.grad)
        loss = ((forward_torch(SPEC, p, torch.from_numpy(xs)) - torch.from_numpy(ys)) ** 2).mean((1, 2)).sum()
        topt.zero_grad()
        loss.backward()
        topt.step()
    moved = np.abs(net.flat - theta).max()
    assert moved > 1e-2  # the fit really moved the parameters
    np.testing.assert_allclose(net.flat, p.detach().numpy(), atol=2e-5 * max(1.0, moved))


def test_unknown_optimizer_is_one_clear_error():
    with pytest.raises(ValueError, match="unknown cloning optimizer 'lbfgs'"):
        make_optimizer("lbfgs", (2, 3), 1e-3)
