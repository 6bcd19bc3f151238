"""Compiled (Numba) kernels of the shaping layer: ``M_phi``'s and the clones' training loops, and
``M_phi``'s labelling forward, each one call for a whole generation's work.

Why hand-written: the nets are tiny (``M_phi`` ~40 -> 20 -> 20 -> 2 on minibatches of 64, the policy
38 -> 32 -> 32 -> 2 on 64-256 rows) and trained for hundreds of steps a generation, so the cost of the
NumPy versions (``lean_mlp.py``, ``population_mlp.py``: ~25 array calls a step) and of torch (per-op
dispatch) is call overhead, not arithmetic; no library fuses forward, backward and Adam over *many*
tiny steps into one call. Here one ``@njit(nogil=True)`` call runs all of a fit's steps (minibatch
gather and input normalization included), which also lets ``M_phi``'s training thread run beside the
master without holding the GIL.

The maths is exactly the NumPy reference's (same parameter layout, same minibatch rows, Adam with
PyTorch's bias correction and the reference's float32 rounding order); only summation order (loops
instead of BLAS) and ``tanh`` (a float32 rational approximation, a few ulp from ``np.tanh``, as Eigen's)
differ, so parameters agree with the reference to float tolerance (``tests/shaping/test_kernels.py``:
rtol 1e-4 after 50 steps). The NumPy classes stay the reference implementation;
``SHAPED_ES_KERNELS=0`` in the environment makes every caller use them instead.

Layout (as ``policies.MLPSpec`` and ``LeanMLP``): for each layer ``W_l`` ``(in_l, out_l)`` row-major,
then ``b_l`` ``(out_l,)``. ``sizes = (in, h_1, ..., out)``; hidden layers ReLU (``relu=True``,
``M_phi``) or tanh (policies); the output layer tanh.
"""

from __future__ import annotations

import os
import time

import numba as nb
import numpy as np

from shaped_es.shaping.param_noise import GOLDEN, INV_2_16, MIX1, MIX2, SCALE

ENABLED = os.environ.get("SHAPED_ES_KERNELS", "1") != "0"

_FM = {"contract", "reassoc", "nsz"}  # FMA and reordered sums in the products; no assumptions on NaN/inf
_F32 = np.float32


@nb.njit(cache=True, error_model="numpy", inline="always")
def _tanh(x):
    """float32 ``tanh``: Eigen's rational approximation (clamped to +-7.9053; |x| < 4e-4 -> x); a few
    ulp from ``np.tanh``, and branch-free, so it vectorizes (``np.tanh`` in Numba is a scalar libm call)."""
    c = min(max(x, _F32(-7.90531110763549805)), _F32(7.90531110763549805))
    x2 = c * c
    p = x2 * _F32(-2.76076847742355e-16) + _F32(2.00018790482477e-13)
    p = x2 * p + _F32(-8.60467152213735e-11)
    p = x2 * p + _F32(5.12229709037114e-08)
    p = x2 * p + _F32(1.48572235717979e-05)
    p = x2 * p + _F32(6.37261928875436e-04)
    p = x2 * p + _F32(4.89352455891786e-03)
    p = c * p
    q = x2 * _F32(1.19825839466702e-06) + _F32(1.18534705686654e-04)
    q = x2 * q + _F32(2.26843463243900e-03)
    q = x2 * q + _F32(4.89352518554385e-03)
    t = p / q
    return c if abs(c) < _F32(0.0004) else t


@nb.njit(cache=True, error_model="numpy", inline="always")
def _view(buf, l, stride, B, w):
    """Layer ``l``'s ``(B, w)`` block of a flat scratch buffer (C-contiguous, for BLAS)."""
    return buf[l * stride : l * stride + B * w].reshape(B, w)


@nb.njit(cache=True, error_model="numpy")
def _layer_buffers(sizes, B):
    """``(stride, H)``: the activations' flat scratch for ``B`` rows, one block of ``stride = B * max
    width`` per layer input and output (``(L + 1) * stride`` float32 zeros; blocks by :func:`_view`)."""
    maxw = 0
    for s in sizes:
        maxw = max(maxw, s)
    stride = B * maxw
    return stride, np.zeros(sizes.shape[0] * stride, np.float32)


@nb.njit(cache=True, error_model="numpy", fastmath=_FM)
def _forward(theta, sizes, relu, H, stride, B):
    """Forward pass of ``B`` rows: layer ``l``'s input is ``_view(H, l, ...)`` ``(B, in_l)`` (``l = 0``:
    the data); fills ``_view(H, l + 1, ...)`` ``(B, out_l)`` per layer."""
    L = sizes.shape[0] - 1
    off = 0
    for l in range(L):
        n_in, n_out = sizes[l], sizes[l + 1]
        boff = off + n_in * n_out
        W = theta[off:boff].reshape(n_in, n_out)
        a = _view(H, l + 1, stride, B, n_out)
        np.dot(_view(H, l, stride, B, n_in), W, a)  # (B, in) @ (in, out): BLAS
        if l == L - 1 or not relu:
            for r in range(B):
                for j in range(n_out):
                    a[r, j] = _tanh(a[r, j] + theta[boff + j])
        else:
            for r in range(B):
                for j in range(n_out):
                    a[r, j] = max(a[r, j] + theta[boff + j], _F32(0.0))
        off = boff + n_out


@nb.njit(cache=True, error_model="numpy", fastmath=_FM)
def _backward(theta, sizes, relu, H, stride, B, y, scale, grad, G, Gp):
    """``grad`` = d/dtheta of ``scale / 2 * sum (f(x) - y)^2`` (``scale = 2 w / (B * out)``: ``w`` times
    the mean squared error's gradient); returns ``sum (f(x) - y)^2`` (float64). ``H`` from
    :func:`_forward`; ``G``, ``Gp`` flat scratch of ``B * max width``."""
    L = sizes.shape[0] - 1
    n_out = sizes[L]
    out = _view(H, L, stride, B, n_out)
    g = G[: B * n_out].reshape(B, n_out)
    sse = 0.0
    for r in range(B):
        for j in range(n_out):
            d = out[r, j] - y[r, j]
            sse += d * d
            g[r, j] = d * scale * (_F32(1.0) - out[r, j] * out[r, j])  # dL/da of the tanh output
    offs = np.empty(L + 1, np.int64)  # where each layer's W starts
    offs[0] = 0
    for l in range(L):
        offs[l + 1] = offs[l] + sizes[l] * sizes[l + 1] + sizes[l + 1]
    for l in range(L - 1, -1, -1):
        n_in, n_out = sizes[l], sizes[l + 1]
        off = offs[l]
        boff = off + n_in * n_out
        g = G[: B * n_out].reshape(B, n_out)  # dL/da_l
        h = _view(H, l, stride, B, n_in)
        np.dot(h.T, g, grad[off:boff].reshape(n_in, n_out))  # gW (in, out)
        for j in range(n_out):
            grad[boff + j] = _F32(0.0)
        for r in range(B):
            for j in range(n_out):
                grad[boff + j] += g[r, j]
        if l:
            gp = Gp[: B * n_in].reshape(B, n_in)
            np.dot(g, theta[off:boff].reshape(n_in, n_out).T, gp)  # dL/dh_l (B, in)
            if relu:
                for r in range(B):
                    for k in range(n_in):
                        gp[r, k] = gp[r, k] if h[r, k] > _F32(0.0) else _F32(0.0)
            else:
                for r in range(B):
                    for k in range(n_in):
                        gp[r, k] *= _F32(1.0) - h[r, k] * h[r, k]
            G, Gp = Gp, G
    return sse


@nb.njit(cache=True, error_model="numpy")
def _adam(p, g, m, v, t, lr, b1, b2, eps):
    """One Adam step in place, rounded as ``lean_mlp.FlatAdam.step`` rounds it (float32, the bias
    correction of the denominator in float64); no FMA contraction, so each product rounds as NumPy's."""
    c1, c1m = _F32(b1), _F32(1.0 - b1)
    c2, c2m = _F32(b2), _F32(1.0 - b2)
    bc2 = np.sqrt(1.0 - b2 ** t)  # float64, as np.sqrt(python float) in the reference
    step = _F32(lr / (1.0 - b1 ** t))
    e = _F32(eps)
    for i in range(p.shape[0]):
        gi = g[i]
        mi = m[i] * c1 + gi * c1m
        vi = v[i] * c2 + (gi * gi) * c2m
        m[i], v[i] = mi, vi
        den = _F32(np.float64(np.sqrt(vi)) / bc2) + e
        p[i] -= (mi / den) * step


@nb.njit(cache=True, error_model="numpy")
def _sgd(p, g, lr):
    s = _F32(lr)
    for i in range(p.shape[0]):
        p[i] -= s * g[i]


@nb.njit(cache=True, error_model="numpy", nogil=True)
def fit_mphi(theta, m, v, t0, sizes, X, Y, idx, shift, scale, clip, lr, b1, b2, eps, losses):
    """``M_phi``'s training steps (``inverse_dynamics.InverseDynamics.train``): step ``k`` is one Adam
    step on the MSE of rows ``idx[k]`` ``(B,)`` of the data set ``X`` ``(N, in)``, ``Y`` ``(N, act)``, the
    inputs standardized as ``RunningNorm.apply`` (``(x - shift) * scale`` clipped to ``+-clip``).
    ``theta``, ``m``, ``v`` ``(n,)`` float32 in place; Adam's step count runs from ``t0 + 1``; the
    loss of every step goes to ``losses`` ``(steps,)``."""
    steps, B = idx.shape
    n_in, n_act = X.shape[1], Y.shape[1]
    stride, H = _layer_buffers(sizes, B)
    x0 = _view(H, 0, stride, B, n_in)
    y = np.empty((B, n_act), np.float32)
    G = np.zeros(stride, np.float32)
    Gp = np.zeros(stride, np.float32)
    grad = np.zeros(theta.shape[0], np.float32)
    c = _F32(clip)
    sc = _F32(2.0 / (B * n_act))
    for k in range(steps):
        for r in range(B):
            row = idx[k, r]
            for i in range(n_in):
                z = (X[row, i] - shift[i]) * scale[i]
                x0[r, i] = min(max(z, -c), c)
            for j in range(n_act):
                y[r, j] = Y[row, j]
        _forward(theta, sizes, True, H, stride, B)
        sse = _backward(theta, sizes, True, H, stride, B, y, sc, grad, G, Gp)
        losses[k] = sse / (B * n_act)
        _adam(theta, grad, m, v, t0 + k + 1, lr, b1, b2, eps)


@nb.njit(cache=True, error_model="numpy", inline="always")
def _normal(seed, counter):
    """``param_noise.normals``' element ``counter`` for ``seed`` (uint64s), with its constants: splitmix64, then the
    scaled sum of its four 16-bit parts."""
    x = seed + (counter + np.uint64(1)) * GOLDEN
    x = (x ^ (x >> np.uint64(30))) * MIX1
    x = (x ^ (x >> np.uint64(27))) * MIX2
    x = x ^ (x >> np.uint64(31))
    m = np.uint64(0xFFFF)
    total = _F32((x & m) + ((x >> np.uint64(16)) & m) + ((x >> np.uint64(32)) & m) + (x >> np.uint64(48)))
    return (total * INV_2_16 - _F32(2.0)) * SCALE


@nb.njit(cache=True, error_model="numpy", nogil=True)
def fit_population(theta, S, A, weight, adam, lr, b1, b2, eps, sizes, noise, noise_seeds):
    """Behaviour cloning's steps (``population_fit.fit_rows``): member ``p`` (row ``p`` of ``theta``
    ``(P, n)``, in place) takes ``S.shape[0]`` steps, step ``k`` on rows ``S[k, p]`` ``(B, obs)`` with
    labels ``A[k, p]`` ``(B, act)``, gradient ``weight[p]`` times that of their mean squared error; Adam
    (fresh state, as ``make_optimizer``) or plain SGD. Tanh on every layer (``policies.forward``).
    ``noise`` > 0: each step's gradient is taken at ``theta_p + noise * z_k`` (``z_k`` =
    ``param_noise.normals(noise_seeds[p], k, n)``, drawn here element by element; ``noise_seeds`` ``(P,)``
    uint64) and applied to ``theta_p``."""
    steps, P, B = S.shape[0], S.shape[1], S.shape[2]
    n_obs, n_act = S.shape[3], A.shape[3]
    n = theta.shape[1]
    stride, H = _layer_buffers(sizes, B)
    x0 = _view(H, 0, stride, B, n_obs)
    G = np.zeros(stride, np.float32)
    Gp = np.zeros(stride, np.float32)
    grad = np.zeros(n, np.float32)
    m = np.zeros(n, np.float32)
    v = np.zeros(n, np.float32)
    noisy = noise > 0.0
    at = np.empty(n if noisy else 0, np.float32)  # theta_p + noise z_k, where the gradient is taken
    s = _F32(noise)
    for p in range(P):
        sc = _F32(2.0 / (B * n_act)) * _F32(weight[p])
        th = theta[p]
        m[:] = 0.0
        v[:] = 0.0
        for k in range(steps):
            x = S[k, p]
            for r in range(B):
                for i in range(n_obs):
                    x0[r, i] = x[r, i]
            w = th  # where the gradient is taken
            if noisy:
                seed, base = np.uint64(noise_seeds[p]), np.uint64(k) * np.uint64(n)
                for i in range(n):
                    at[i] = th[i] + s * _normal(seed, base + np.uint64(i))
                w = at
            _forward(w, sizes, False, H, stride, B)
            _backward(w, sizes, False, H, stride, B, A[k, p], sc, grad, G, Gp)
            if adam:
                _adam(th, grad, m, v, k + 1, lr, b1, b2, eps)
            else:
                _sgd(th, grad, lr)


@nb.njit(cache=True, error_model="numpy", nogil=True)
def label_mphi(theta, sizes, S, Q, shift, scale, clip, out):
    """``M_phi``'s labels (``InverseDynamics.label``): rows of states ``S`` ``(N, obs)`` and queries ``Q``
    ``(N, d)``, standardized and clipped as in :func:`fit_mphi`, through the net; ``out`` ``(N, act)``."""
    N, n_obs, d = S.shape[0], S.shape[1], Q.shape[1]
    L = sizes.shape[0] - 1
    CH = 256  # rows per forward pass (cache-sized)
    stride, H = _layer_buffers(sizes, CH)
    c = _F32(clip)
    for r0 in range(0, N, CH):
        nr = min(CH, N - r0)
        x0 = _view(H, 0, stride, nr, n_obs + d)
        for r in range(nr):
            for i in range(n_obs):
                z = (S[r0 + r, i] - shift[i]) * scale[i]
                x0[r, i] = min(max(z, -c), c)
            for i in range(d):
                z = (Q[r0 + r, i] - shift[n_obs + i]) * scale[n_obs + i]
                x0[r, n_obs + i] = min(max(z, -c), c)
        _forward(theta, sizes, True, H, stride, nr)
        res = _view(H, L, stride, nr, out.shape[1])
        for r in range(nr):
            for j in range(out.shape[1]):
                out[r0 + r, j] = res[r, j]


@nb.njit(cache=True, error_model="numpy", nogil=True)
def take_block_rows(src, block, local, b, out):
    """``out[i] = src[local[i]]`` for every draw ``i`` with ``block[i] == b`` (``member_rows.MemberRows.
    gather``, one block of rows at a time, without NumPy's temporary and scatter)."""
    w = src.shape[1]
    for i in range(block.shape[0]):
        if block[i] == b:
            r = local[i]
            for j in range(w):
                out[i, j] = src[r, j]


@nb.njit(cache=True, error_model="numpy", nogil=True)
def column_stats(x):
    """``(mean, sum of squared deviations)`` ``(d,)`` float64 of the rows of ``x`` ``(N, d)`` float32 (two
    passes, float64 sums; ``inverse_dynamics.RunningNorm.update`` without its float64 copy of ``x``)."""
    N, d = x.shape
    mean = np.zeros(d)
    m2 = np.zeros(d)
    for r in range(N):
        for j in range(d):
            mean[j] += x[r, j]
    for j in range(d):
        mean[j] /= max(N, 1)
    for r in range(N):
        for j in range(d):
            z = x[r, j] - mean[j]
            m2[j] += z * z
    return mean, m2


def cached(fns=None) -> bool | None:
    """Whether Numba's cache holds a compile of each of ``fns`` (default: the kernels :func:`warm_up`
    calls, which compile the rest) for this machine, this Numba and this source, so that a run loads them
    (~0.1-0.5 s) instead of compiling them (8-30 s: the first run after an install, an edit of this file,
    another CPU or Numba). None if Numba's cache cannot be read this way (its internals changed)."""
    try:
        from numba.core.registry import cpu_target

        codegen = cpu_target.target_context.codegen()
        for fn in fns or (fit_mphi, fit_population, label_mphi, column_stats, take_block_rows):
            if fn.overloads:  # compiled (or loaded) in this process already
                continue
            cache, files = fn._cache, fn._cache._cache_file
            index = files._load_index()  # {} when missing or stale (another source stamp or Numba)
            if not any(cache._index_key(key[0], codegen) == key and os.path.exists(files._data_path(name))
                       for key, name in index.items()):
                return False
        return True
    except Exception:  # noqa: BLE001 - Numba's private cache API: unknown rather than wrong
        return None


def warm_up() -> float:
    """Compile (or load from Numba's cache) every kernel on tiny data; returns the seconds it took (the
    first generation would otherwise pay them)."""
    t0 = time.perf_counter()
    sizes = np.array([3, 4, 2], np.int64)
    n = 3 * 4 + 4 + 4 * 2 + 2
    th = np.zeros(n, np.float32)
    X, Y = np.zeros((5, 3), np.float32), np.zeros((5, 2), np.float32)
    idx = np.zeros((2, 4), np.int64)
    f3 = np.ones(3, np.float32)
    fit_mphi(th, th.copy(), th.copy(), 0, sizes, X, Y, idx, f3, f3, 10.0, 1e-3, 0.9, 0.999, 1e-8,
             np.zeros(2))
    S, A = np.zeros((2, 1, 4, 3), np.float32), np.zeros((2, 1, 4, 2), np.float32)
    fit_population(th[None].copy(), S, A, np.ones(1, np.float32), True, 1e-3, 0.9, 0.999, 1e-8, sizes, 0.0,
                   np.zeros(1, np.uint64))
    label_mphi(th, sizes, X[:, :2].copy(), X[:, :1].copy(), f3, f3, 10.0, np.zeros((5, 2), np.float32))
    column_stats(X)
    take_block_rows(X, np.zeros(5, np.int64), np.zeros(5, np.int64), 0, np.zeros((5, 3), np.float32))
    return time.perf_counter() - t0
