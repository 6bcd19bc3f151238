import numpy as np
import torch

from shaped_es.policies import MLPSpec, forward, forward_torch


def test_mlp_layout_and_forward_matches_manual():
    spec = MLPSpec(3, 2, (4,))
    assert spec.num_params == 3 * 4 + 4 + 4 * 2 + 2
    theta = np.arange(spec.num_params, dtype=np.float32) / 100
    obs = np.array([[[0.1, -0.2, 0.3]]], dtype=np.float32)  # (1, 1, 3)
    W1 = theta[:12].reshape(3, 4)
    b1 = theta[12:16]
    W2 = theta[16:24].reshape(4, 2)
    b2 = theta[24:26]
    want = np.tanh(np.tanh(obs[0, 0] @ W1 + b1) @ W2 + b2)
    got = forward(spec, theta[None], obs)
    np.testing.assert_allclose(got[0, 0], want, rtol=1e-6)


def test_forward_population_and_torch_twin():
    spec = MLPSpec(5, 3, (8, 8))
    P = np.stack([spec.init(i) for i in range(4)]) + 0.3  # (4, n)
    obs = np.random.default_rng(0).normal(size=(4, 6, 5)).astype(np.float32)
    out = forward(spec, P, obs)
    assert out.shape == (4, 6, 3) and np.abs(out).max() <= 1
    for i in range(4):  # each member's actions depend on its own parameters only
        np.testing.assert_allclose(forward(spec, P[i : i + 1], obs[i : i + 1])[0], out[i], rtol=1e-6)
    t = forward_torch(spec, torch.from_numpy(P), torch.from_numpy(obs)).numpy()
    np.testing.assert_allclose(t, out, atol=1e-5)


def test_rowwise_forward_rows_do_not_depend_on_the_batch():
    """rowwise: a row's action is the same, bit for bit, whether it is computed alone or among other rows
    (one BLAS matrix product over the batch rounds rows differently by batch size, so evaluate's chunk of
    episodes acted differently from load_policy(...).predict(obs) on one observation); the default
    batched product agrees to float rounding."""
    spec = MLPSpec(38, 2, (32, 32))  # CarNav-v0's observation and action sizes
    rng = np.random.default_rng(1)
    P = rng.normal(0, 0.3, (3, spec.num_params)).astype(np.float32)
    obs = rng.normal(size=(3, 40, 38)).astype(np.float32)
    out = forward(spec, P, obs, rowwise=True)  # (3, 40, 2)
    np.testing.assert_allclose(forward(spec, P, obs), out, atol=1e-5)
    for p in range(3):
        alone = np.stack([forward(spec, P[p : p + 1], obs[p : p + 1, b : b + 1], rowwise=True)[0, 0]
                          for b in range(40)])
        np.testing.assert_array_equal(alone, out[p])
        for k in (2, 7, 15):  # any chunk of the rows
            np.testing.assert_array_equal(forward(spec, P[p : p + 1], obs[p : p + 1, :k], rowwise=True)[0],
                                          out[p, :k])
    strided = np.asfortranarray(obs[0, ::2])[None]  # a non-contiguous batch takes the same path
    np.testing.assert_array_equal(forward(spec, P[:1], strided, rowwise=True)[0], out[0, ::2])
