"""The compiled kernels (shaping/kernels.py) against the NumPy reference (lean_mlp.py, population_mlp.py)
on fixed data: the same losses and parameters to float tolerance (summation order and the float32 tanh
approximation are all that differ), and a shaped run that resumes exactly with them on."""

from __future__ import annotations

import numpy as np
import pytest

from helpers import new_run, run_until_crash, strip_time, train
from shaped_es.policies import MLPSpec
from shaped_es.shaping import kernels
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.lean_mlp import FlatAdam, LeanMLP
from shaped_es.shaping.population_fit import FitTask, fit_rows
from shaped_es.shaping.population_mlp import PopulationMLP, make_optimizer
from shaped_es.shaping.settings import InverseDynamicsConfig
from shaped_es.trainer import Trainer

RTOL = 1e-4  # parameters after 50-200 steps (measured: ~1e-6 after 200)


def _rel(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b))) / np.max(np.abs(b)))


def test_tanh_approximation_is_within_a_few_ulp():
    x = np.linspace(-12, 12, 200_001, dtype=np.float32)
    out = np.zeros((1, x.size), np.float32)
    sizes = np.array([1, 1], np.int64)  # one tanh unit: out = tanh(1 * x + 0)
    H = np.zeros(2 * x.size, np.float32)
    H[: x.size] = x
    kernels._forward(np.array([1.0, 0.0], np.float32), sizes, False, H, x.size, x.size)
    out = H[x.size :]
    assert np.max(np.abs(out - np.tanh(x))) < 1e-6
    assert np.all(np.abs(out) <= 1.0)


@pytest.mark.parametrize("hidden", [(20, 20), (20, 20, 20)])
def test_mphi_fit_equals_the_numpy_steps(hidden):
    rng = np.random.default_rng(0)
    sizes = (42, *hidden, 2)
    net = LeanMLP(sizes, np.random.default_rng(1))
    opt = FlatAdam(net.num_params, lr=1e-3)
    X = rng.standard_normal((3000, 42)).astype(np.float32) * 3
    Y = np.tanh(rng.standard_normal((3000, 2))).astype(np.float32)
    shift = (rng.standard_normal(42) * 0.1).astype(np.float32)
    scale = (0.5 + rng.random(42)).astype(np.float32)
    steps, B = 200, 64
    idx = rng.integers(0, 3000, size=(steps, B))
    theta, m, v = net.flat.copy(), np.zeros(net.num_params, np.float32), np.zeros(net.num_params, np.float32)
    losses = np.zeros(steps)
    kernels.fit_mphi(theta, m, v, 0, np.array(sizes, np.int64), X, Y, idx, shift, scale, 10.0, 1e-3, 0.9,
                     0.999, 1e-8, losses)
    ref = []
    for k in range(steps):
        x = np.clip((X[idx[k]] - shift) * scale, -10.0, 10.0).astype(np.float32)
        ref.append(net.mse_backward(x, Y[idx[k]]))
        opt.step(net.flat, net.grad)
    np.testing.assert_allclose(losses, ref, rtol=1e-5)
    assert _rel(theta, net.flat) < RTOL
    assert _rel(m, opt.m) < RTOL and _rel(v, opt.v) < 1e-3
    assert losses[-20:].mean() < losses[:20].mean()  # it learns


def test_inverse_dynamics_train_and_label_match_the_reference(make_transitions, monkeypatch):
    tr = make_transitions(np.random.default_rng(3), episodes=4, steps=50)
    cfg = InverseDynamicsConfig(steps_per_generation=60, seed=5, filter="none")
    models = [InverseDynamics(tr.state.shape[1], tr.position.shape[1], tr.action.shape[1], cfg) for _ in range(2)]
    for mdl in models:
        mdl.add([tr])
    fast = models[0].train()
    monkeypatch.setattr(kernels, "ENABLED", False)
    slow = models[1].train()
    np.testing.assert_allclose(fast, slow, rtol=1e-5)
    a, b = (mdl.state_dict() for mdl in models)
    assert a["meta/iterations"][0] == b["meta/iterations"][0] == 60 and a["optim/t"][0] == 60
    np.testing.assert_array_equal(a["rng/state"], b["rng/state"])  # the same draws were taken
    assert _rel(a["net/flat"], b["net/flat"]) < RTOL
    q = tr.waypoint - tr.position
    ref = models[0].label(tr.state, q)  # NumPy path (kernels off)
    monkeypatch.setattr(kernels, "ENABLED", True)
    np.testing.assert_allclose(models[0].label(tr.state, q), ref, atol=1e-6)
    np.testing.assert_allclose(models[0].label(tr.state[None, :7], q[None, :7]), ref[None, :7], atol=1e-6)


@pytest.mark.parametrize("optimizer", ["adam", "sgd"])
def test_population_fit_equals_the_numpy_steps(optimizer, monkeypatch):
    rng = np.random.default_rng(0)
    spec = MLPSpec(9, 2, (16, 8))
    P, steps, B = 3, 50, 32
    theta = np.stack([spec.init(i) for i in range(P)])  # (P, n)
    S = rng.standard_normal((steps + 2, P + 1, B, 9)).astype(np.float32)[:, 1:]  # a strided view, as a chunk
    A = np.tanh(rng.standard_normal((steps + 2, P, B, 2))).astype(np.float32)
    has = np.array([True, False, True])  # member 1 has no data: no gradient
    task = FitTask(spec, theta, S, A, has, steps, optimizer, 3e-3, k_eval=2)
    got = fit_rows(task)
    monkeypatch.setattr(kernels, "ENABLED", False)
    ref = fit_rows(task)
    assert _rel(got[0], ref[0]) < RTOL
    np.testing.assert_array_equal(got[0][1], theta[1])
    np.testing.assert_allclose(got[2], ref[2], rtol=1e-4)  # losses after, on the eval rows
    # and the reference itself is the population MLP's steps
    net = PopulationMLP(spec, theta)
    opt = make_optimizer(optimizer, net.flat.shape, 3e-3)
    for k in range(steps):
        net.mse_backward(S[k], A[k], has.astype(np.float32))
        opt.step(net.flat, net.grad)
    np.testing.assert_array_equal(ref[0], net.flat)


@pytest.mark.parametrize("optimizer", ["adam", "sgd"])
def test_a_noisy_fit_equals_the_numpy_steps_and_differs_from_a_plain_one(optimizer, monkeypatch):
    """``noise`` > 0: the compiled fit draws each step's z element by element, as ``param_noise.normals``."""
    rng = np.random.default_rng(3)
    spec = MLPSpec(9, 2, (16, 8))
    P, steps, B = 2, 40, 32
    theta = np.stack([spec.init(i) for i in range(P)])  # (P, n)
    S = rng.standard_normal((steps, P, B, 9)).astype(np.float32)
    A = np.tanh(rng.standard_normal((steps, P, B, 2))).astype(np.float32)
    noisy = FitTask(spec, theta, S, A, np.ones(P, bool), steps, optimizer, 3e-3, k_eval=2, noise=0.05,
                    noise_seeds=np.array([7, 2**63 + 5], np.uint64))
    got = fit_rows(noisy)[0]
    plain = fit_rows(FitTask(spec, theta, S, A, np.ones(P, bool), steps, optimizer, 3e-3, k_eval=2))[0]
    monkeypatch.setattr(kernels, "ENABLED", False)
    ref = fit_rows(noisy)[0]
    assert _rel(got, ref) < RTOL
    assert _rel(got, plain) > 10 * max(_rel(got, ref), RTOL)  # the noise moved the fit
    with pytest.raises(ValueError, match="noise seed per member"):
        fit_rows(FitTask(spec, theta, S, A, np.ones(P, bool), steps, optimizer, 3e-3, k_eval=2, noise=0.05))


def test_mean_clone_size_fit_matches_over_200_steps():
    """The candidate mechanism's clone: one member, 256 rows a step, 200 steps (CarNav-v0's policy)."""
    rng = np.random.default_rng(1)
    spec = MLPSpec(38, 2, (32, 32))
    theta = spec.init(0)[None]
    S = rng.standard_normal((200, 1, 256, 38)).astype(np.float32)
    A = np.tanh(rng.standard_normal((200, 1, 256, 2))).astype(np.float32)
    th = theta.copy()
    kernels.fit_population(th, S, A, np.ones(1, np.float32), True, 3e-3, 0.9, 0.999, 1e-8,
                           np.array(spec.sizes, np.int64), 0.0, np.zeros(1, np.uint64))
    net = PopulationMLP(spec, theta)
    opt = make_optimizer("adam", net.flat.shape, 3e-3)
    for k in range(200):
        net.mse_backward(S[k], A[k], np.ones(1, np.float32))
        opt.step(net.flat, net.grad)
    assert _rel(th, net.flat) < RTOL


CAR = {"env": "CarNav-v0", "executor": "inline", "method": "shaped", "generations": 4, "seed": 2,
       "es": {"pairs": 4}, "policy": {"hidden": [8]},
       "rollout": {"episodes": 1, "test_episodes": 1, "max_steps": 40},
       "shaping": {"inverse_dynamics": {"steps_per_generation": 40, "filter": "none", "babble": 2},
                   "history": 2, "mean_clone": {"steps": 20, "batch_size": 32}},
       "tensorboard": False}


def test_a_shaped_run_with_the_kernels_resumes_exactly(tmp_path, monkeypatch):
    assert kernels.ENABLED
    full = train(tmp_path / "full", CAR).read_metrics()
    assert full[-1]["shaping_active"] == "1" and int(full[-1]["mphi_iterations"]) > 0
    cfg, store = new_run(tmp_path / "crashed", CAR)
    run_until_crash(monkeypatch, cfg, store, 3)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full)


def test_the_data_set_fifo_keeps_the_newest_rows_in_order(make_transitions, monkeypatch):
    """M_phi's data set in its backing buffers equals the concatenate-and-cut FIFO, across many adds
    (the buffers fill, the kept rows move to the front) and a set_data in between; the normalizer's
    compiled statistics equal the float64 NumPy ones."""
    cfg = InverseDynamicsConfig(max_dataset=100, filter="none")
    mdl = InverseDynamics(4, 2, 2, cfg)
    ref_x = np.zeros((0, 6), np.float32)
    rng = np.random.default_rng(0)
    for i in range(12):
        tr = make_transitions(rng, episodes=1, steps=int(rng.integers(2, 60)), obs_dim=4)
        mdl.add([tr])
        x, _ = mdl.newest(len(tr) - 1)
        ref_x = np.concatenate([ref_x, x])[-100:]
        np.testing.assert_array_equal(mdl.state_dict()["data/x"], ref_x)
        if i == 6:
            mdl.set_data(ref_x[:50], np.zeros((50, 2), np.float32))
            ref_x = ref_x[:50]
    x = rng.standard_normal((1000, 6)).astype(np.float32) * 5 + 3
    mean, m2 = kernels.column_stats(x)
    np.testing.assert_allclose(mean, x.astype(np.float64).mean(0), rtol=1e-12)
    np.testing.assert_allclose(m2, ((x.astype(np.float64) - mean) ** 2).sum(0), rtol=1e-10)


TINY_KERNEL = "import numba\n\n\n@numba.njit(cache=True)\ndef double(x):\n    return 2 * x\n"


def _load_tiny(path):
    """A fresh dispatcher of ``path``'s ``double`` (a new module object, as a new process would have)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("tiny_kernel", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.double


def test_cached_tells_a_cold_numba_cache_from_a_warm_one(tmp_path):
    """``kernels.cached`` reads Numba's on-disk cache: no compile yet -> False; compiled (by an earlier
    process: a fresh dispatcher) -> True; the source edited since -> False (Numba compiles again)."""
    path = tmp_path / "tiny_kernel.py"
    path.write_text(TINY_KERNEL)
    first = _load_tiny(path)
    assert kernels.cached([first]) is False
    assert first(2.0) == 4.0  # compiles, and saves it in the cache
    assert kernels.cached([first]) is True  # compiled in this process
    again = _load_tiny(path)
    assert not again.overloads and kernels.cached([again]) is True  # ... and on disk
    path.write_text(TINY_KERNEL + "\n# edited\n")
    assert kernels.cached([_load_tiny(path)]) is False
    assert kernels.cached([lambda x: x]) is None  # not a Numba dispatcher: cannot tell
