"""Behaviour cloning of a whole population at once: ``theta_i -> theta*_i`` (paper, Sec. III, Eq. L(theta)).

Worker ``i`` fits its policy, starting from its own ``theta_i``, to the inverse-dynamics labels
``a_hat = M_phi(s_t, w_t)`` of its aggregated data set ``D_i`` (DAgger style) by a few gradient steps on

    L(theta) = 1/M sum_t (pi_theta(s_t) - M_phi(s_t, w_t))^2                (Eq. L(theta); MSE)

All ``P`` members are cloned in one batched computation. :func:`clone_population` (the full-data
reference, torch): the flat parameter matrix ``(P, n)`` is the leaf tensor,
:func:`shaped_es.policies.forward_torch` evaluates every member on its own minibatch, and the summed
loss ``sum_i L_i(theta_i)`` has gradient ``dL_i/dtheta_i`` in row ``i``. Adam and SGD act elementwise, so
row ``i`` follows exactly the trajectory it would follow if cloned alone, given the same minibatch indices
-- which come from a per-member NumPy generator seeded by ``seeds[i]``.

The MSE is the mean over samples and action dimensions (the ``1/M`` of the paper, also over actions).

:func:`clone_sampled` is the fast form the method uses: it draws every member's minibatch rows first and
labels only those rows (labels are per row, so they are the labels a full labelling would give there),
then clones with the NumPy population kernel (``population_mlp``, the same steps as torch's to float
tolerance; in chunks on local workers through shared memory when given them); its
``loss_before``/``loss_after`` are measured on the first ``eval_batches`` minibatches' rows, not on all of
``D_i`` (a full-data MSE cost as much as the cloning itself).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from shaped_es.policies import MLPSpec, ObsNorm, forward_torch
from shaped_es.shaping.member_rows import MemberRows
from shaped_es.shaping.population_fit import FitTask, fit_rows
from shaped_es.shaping.shared_rows import SharedRows
from shaped_es.shaping.settings import CloningConfig


@dataclass
class CloneResult:
    theta_star: np.ndarray  # (P, n) float32, the cloned parameters theta*_i
    loss_before: np.ndarray  # (P,) float64, MSE to the labels over D_i at theta_i (nan: member has no data)
    loss_after: np.ndarray  # (P,) float64, the same at theta*_i
    samples: np.ndarray  # (P,) int64, samples of D_i used
    label_std: float = float("nan")  # spread of the labels used (a collapsed M_phi gives ~0)
    reference: dict | None = None  # label quality vs a reference policy (clone_sampled, when given one)
    fit_cpu_time_s: float = 0.0  # CPU of gradient steps run in other processes (clone_sampled's map_fit)


def pad_population(
    states: Sequence[np.ndarray], labels: Sequence[np.ndarray], max_samples: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per-member ``(T_i, obs)``, ``(T_i, act)`` -> padded ``(P, T, obs)``, ``(P, T, act)``, mask ``(P, T)``.

    With ``max_samples > 0`` only the last ``max_samples`` rows of each member are kept (newest data).
    """
    if len(states) != len(labels):
        raise ValueError(f"{len(states)} state arrays but {len(labels)} label arrays")
    if max_samples > 0:
        states = [np.asarray(s)[-max_samples:] for s in states]
        labels = [np.asarray(a)[-max_samples:] for a in labels]
    lens = [int(np.asarray(s).shape[0]) for s in states]
    if any(int(np.asarray(a).shape[0]) != n for a, n in zip(labels, lens)):
        raise ValueError("each member needs as many labels as states")
    P, T = len(states), max(lens, default=0)
    obs_dim = np.asarray(states[0]).shape[-1] if P else 0
    act_dim = np.asarray(labels[0]).shape[-1] if P else 0
    S = np.zeros((P, T, obs_dim), np.float32)  # (P, T, obs)
    A = np.zeros((P, T, act_dim), np.float32)  # (P, T, act)
    M = np.zeros((P, T), bool)  # (P, T)
    for i, (s, a, n) in enumerate(zip(states, labels, lens)):
        S[i, :n], A[i, :n], M[i, :n] = s, a, True
    return S, A, M


def _keep_newest(mask: np.ndarray, max_samples: int) -> np.ndarray:
    """Mask ``(P, T)`` restricted to each row's last ``max_samples`` True entries."""
    from_end = np.cumsum(mask[:, ::-1], axis=1)[:, ::-1]  # (P, T) valid entries at or after t
    return mask & (from_end <= max_samples)


def _member_indices(mask: np.ndarray, seeds: np.ndarray, steps: int, batch: int) -> np.ndarray:
    """Minibatch positions ``(steps, P, B)`` into each member's padded rows, from its own generator."""
    P = mask.shape[0]
    out = np.zeros((steps, P, batch), np.int64)
    for i in range(P):
        valid = np.flatnonzero(mask[i])  # (n_i,)
        if valid.size:
            draws = np.random.default_rng(int(seeds[i])).integers(0, valid.size, size=(steps, batch))
            out[:, i] = valid[draws]  # (steps, B)
    return out


def _masked_mse(spec: MLPSpec, params: torch.Tensor, S: torch.Tensor, A: torch.Tensor, M: torch.Tensor,
                chunk: int = 2048) -> np.ndarray:
    """Per-member MSE over all valid samples, in chunks of time to bound memory; ``(P,)`` (nan: no data)."""
    import torch
    P, T = M.shape
    sse = torch.zeros(P, dtype=torch.float64)
    with torch.no_grad():
        for t0 in range(0, T, chunk):
            pred = forward_torch(spec, params, S[:, t0 : t0 + chunk])  # (P, c, act)
            err = ((pred - A[:, t0 : t0 + chunk]) ** 2).sum(-1)  # (P, c)
            sse += (err * M[:, t0 : t0 + chunk]).sum(1).double()
    n = M.sum(1).double() * spec.act_dim  # (P,)
    return torch.where(n > 0, sse / n.clamp(min=1), torch.nan).numpy()


def clone_population(
    spec: MLPSpec,
    theta: np.ndarray,
    states: np.ndarray | Sequence[np.ndarray],
    labels: np.ndarray | Sequence[np.ndarray],
    mask: np.ndarray | None = None,
    config: CloningConfig | None = None,
    seeds: Sequence[int] | np.ndarray | None = None,
) -> CloneResult:
    """Clone every member to its labels: ``theta`` ``(P, n)`` -> :class:`CloneResult` (``theta_star (P, n)``).

    ``states``/``labels``: lists of per-member arrays ``(T_i, obs)``/``(T_i, act)`` (oldest first), or
    padded arrays ``(P, T, obs)``/``(P, T, act)`` with ``mask`` ``(P, T)`` (None: all valid).
    ``seeds`` ``(P,)``: minibatch seed of each member (default from ``config.seed`` and the row index);
    cloning member ``i`` alone with ``seeds=[seeds[i]]`` gives the same ``theta*_i``.
    """
    cfg = config or CloningConfig()
    th = np.atleast_2d(np.asarray(theta, dtype=np.float32))  # (P, n)
    P = th.shape[0]
    if th.shape[1] != spec.num_params:
        raise ValueError(f"theta has {th.shape[1]} parameters, spec needs {spec.num_params}")
    if isinstance(states, np.ndarray) and states.ndim == 3:
        S, A = np.asarray(states, np.float32), np.asarray(labels, np.float32)
        M = np.ones(S.shape[:2], bool) if mask is None else np.asarray(mask, bool)
        if cfg.max_samples > 0:
            M = _keep_newest(M, cfg.max_samples)
        if M.shape == S.shape[:2] == A.shape[:2]:  # padding may hold anything (NaN): zero it
            S = np.where(M[..., None], S, 0).astype(np.float32)  # (P, T, obs)
            A = np.where(M[..., None], A, 0).astype(np.float32)  # (P, T, act)
    else:
        S, A, M = pad_population(list(states), list(labels), cfg.max_samples)
    if S.shape[0] != P or A.shape[:2] != S.shape[:2] or M.shape != S.shape[:2]:
        raise ValueError(f"data shapes {S.shape}, {A.shape}, mask {M.shape} do not match {P} members")
    if S.shape[1] and (S.shape[2] != spec.obs_dim or A.shape[2] != spec.act_dim):
        got, want = (S.shape[2], A.shape[2]), (spec.obs_dim, spec.act_dim)
        raise ValueError(f"data has (obs, act) = {got}, spec needs {want}")
    if seeds is None:
        seeds = [np.random.SeedSequence([cfg.seed, i]).generate_state(1)[0] for i in range(P)]
    seeds = np.asarray(seeds, dtype=np.int64).reshape(-1)
    if seeds.shape[0] != P:
        raise ValueError(f"{seeds.shape[0]} seeds for {P} members")

    import torch  # here, not at the top: a shaped run's clones use the compiled kernels, and torch's import
    # (~2 s) would be every run's start-up

    S_t, A_t, M_t = torch.from_numpy(S), torch.from_numpy(A), torch.from_numpy(M)
    params = torch.tensor(th, requires_grad=True)  # (P, n) leaf: row i is member i
    before = _masked_mse(spec, params, S_t, A_t, M_t)
    n_i = M_t.sum(1)  # (P,)
    if cfg.steps > 0 and S.shape[1] > 0:
        opt = (torch.optim.Adam if cfg.optimizer == "adam" else torch.optim.SGD)([params], lr=cfg.lr)
        rows = torch.arange(P)[:, None]  # (P, 1)
        full = cfg.batch_size <= 0
        idx = None if full else torch.from_numpy(_member_indices(M, seeds, cfg.steps, cfg.batch_size))
        has = (n_i > 0).float()  # (P,) members without data get no gradient
        for k in range(cfg.steps):
            if full:
                s, a, w = S_t, A_t, M_t.float() / n_i.clamp(min=1)[:, None]  # (P, T, .), (P, T)
            else:
                s, a = S_t[rows, idx[k]], A_t[rows, idx[k]]  # (P, B, obs), (P, B, act)
                w = has[:, None].expand(P, cfg.batch_size) / cfg.batch_size  # (P, B)
            err = ((forward_torch(spec, params, s) - a) ** 2).mean(-1)  # (P, B)
            loss = (err * w).sum()  # sum_i L_i(theta_i), Eq. L(theta) per member
            opt.zero_grad(set_to_none=True)
            loss.backward()
            opt.step()
    theta_star = params.detach().numpy().astype(np.float32)  # (P, n)
    after = _masked_mse(spec, params.detach(), S_t, A_t, M_t)
    return CloneResult(theta_star=theta_star, loss_before=before, loss_after=after,
                       samples=n_i.numpy().astype(np.int64))


def warm_up_cloning() -> None:
    """Import and run torch's optimizer machinery once (its first use imports ``torch._dynamo``)."""
    import torch

    p = torch.zeros(1, requires_grad=True)
    opt = torch.optim.Adam([p], lr=1e-3)
    (p * p).sum().backward()
    opt.step()




LabelFn = Callable[[np.ndarray, np.ndarray], np.ndarray]  # states (..., obs), queries (..., d) -> (..., act)


def _label_unique(label_fn: LabelFn, S: np.ndarray, Q: np.ndarray, pos: np.ndarray, n_i: np.ndarray) -> np.ndarray:
    """``label_fn`` on the distinct rows among the draws only (drawn with replacement, about a third of the
    draws repeat a row), scattered back: the same labels, ``(draws, P, B, act)``, for a label source whose
    cost is per row (``ShootLabels``: every candidate action through its model)."""
    offset = np.concatenate([[0], np.cumsum(n_i)[:-1]])  # (P,) member i's rows after the others'
    key = (pos + offset[None, :, None]).reshape(-1)  # (draws P B,) one id per (member, row)
    _, first, inv = np.unique(key, return_index=True, return_inverse=True)
    flat_s, flat_q = S.reshape(-1, S.shape[-1]), Q.reshape(-1, Q.shape[-1])  # (draws P B, obs), (.., d)
    a = np.asarray(label_fn(flat_s[first], flat_q[first]), np.float32)  # (U, act)
    return a[inv.reshape(-1)].reshape(*pos.shape, a.shape[-1])  # (draws, P, B, act)


def clone_sampled(
    spec: MLPSpec,
    theta: np.ndarray,
    data: MemberRows,
    label_fn: LabelFn,
    config: CloningConfig,
    seeds: Sequence[int] | np.ndarray,
    eval_batches: int = 4,
    reference_fn: Callable[[np.ndarray], np.ndarray] | None = None,
    map_fit: Callable | None = None,
    map_chunks: int = 2,
    shared: SharedRows | None = None,
    obs_norm: ObsNorm | None = None,
) -> CloneResult:
    """Clone every member towards ``label_fn`` on its own data: ``theta`` ``(P, n)`` -> ``theta*``.

    ``data`` holds each member's ``D_i`` (oldest first); only the newest ``max_samples`` rows are used.
    Minibatch rows come from ``default_rng(seeds[i])`` exactly as in :func:`clone_population`, which
    gives the same ``theta*`` on fully labelled data. ``batch_size <= 0`` (full data every step)
    labels everything and defers to :func:`clone_population`.

    ``reference_fn(states (..., obs)) -> actions (..., act)``: a fully trained policy; on the eval rows
    ``CloneResult.reference`` then holds the paper's Fig. 5 test loss (mean Euclidean distance of the
    labels to its actions, ``label_ref_error``), the same for the members' own actions before and after
    cloning (``own_ref_error``, ``clone_ref_error``) and the share of rows where the label is closer to
    the reference than the member's own action (``label_beats_own``).

    ``map_fit(fn, tasks) -> results`` (an executor's map): the gradient steps of ``map_chunks`` chunks of
    members run there (:func:`fit_rows` on :class:`FitTask`), after the labels are taken here. With
    ``shared`` (workers on this machine) the rows are gathered into its shared memory and the tasks carry
    only a handle to it.

    ``obs_norm`` (``es.obs_norm``): the normalizer the cloned policies see their observations through;
    the labels (and ``reference_fn``) read the raw states, the fit then runs on their normalized copies:
    ``pi_theta(obs_norm(s)) ~ label(s)``.
    """
    cfg = config
    th = np.atleast_2d(np.asarray(theta, dtype=np.float32))  # (P, n)
    P = th.shape[0]
    seeds = np.asarray(seeds, dtype=np.int64).reshape(-1)
    if data.spans.shape[0] != P or seeds.shape[0] != P:
        raise ValueError(f"data for {data.spans.shape[0]} members, {seeds.shape[0]} seeds for {P} members")
    data = data.newest(cfg.max_samples)
    n_i = data.lengths()  # (P,)
    if cfg.batch_size <= 0:
        states, labels = [], []
        for i in range(P):
            pos = np.arange(n_i[i])[None, None, :]  # (1, 1, n_i)
            one = MemberRows(data.states, data.queries, data.spans[i : i + 1])
            s, q = one.gather(pos)
            states.append(s[0, 0])
            labels.append(label_fn(s[0, 0], q[0, 0]) if n_i[i] else np.zeros((0, spec.act_dim), np.float32))
        if obs_norm is not None:  # the policies' inputs; the labels above read the raw states
            states = [obs_norm.apply(s) for s in states]
        res = clone_population(spec, th, states, labels, config=cfg, seeds=seeds)
        res.label_std = _label_std(labels)
        return res
    steps, B = cfg.steps, cfg.batch_size
    k_eval = max(1, min(eval_batches, steps))
    draws = max(steps, k_eval)
    # every member's draws from its own generator, then one gather per block
    pos = np.zeros((draws, P, B), np.int64)  # (draws, P, B) positions into each D_i
    for i in np.flatnonzero(n_i):
        pos[:, i] = np.random.default_rng(int(seeds[i])).integers(0, n_i[i], size=(draws, B))
    has = n_i > 0  # (P,) members without data get no gradient and nan losses
    fit_elsewhere = map_fit is not None and P >= 2
    ref = None
    if shared is not None and fit_elsewhere:  # gathered and labelled straight into shared memory
        buf, ref = shared.arrays({"S": (draws, P, B, spec.obs_dim), "A": (draws, P, B, spec.act_dim)})
        S, A = buf["S"], buf["A"]
    else:
        S = np.zeros((draws, P, B, spec.obs_dim), np.float32)  # (draws, P, B, obs)
        A = np.zeros((draws, P, B, spec.act_dim), np.float32)  # (draws, P, B, act)
    if has.any():
        Q = data.gather(pos, out_states=S)  # S (draws, P, B, obs) filled; queries (draws, P, B, d)
        if getattr(label_fn, "label_once", False):  # a costly label source: each drawn row labelled once
            A[...] = _label_unique(label_fn, S, Q, pos, n_i)
        else:
            A[...] = label_fn(S, Q)  # (draws, P, B, act) labels a_hat
        if not has.all():
            S[:, ~has], A[:, ~has] = 0.0, 0.0
    else:
        S[...], A[...] = 0.0, 0.0
    s_raw = None  # the eval rows' raw states, for reference_fn (which reads raw states, as the labels)
    if obs_norm is not None:  # the policies' inputs (in place: S may be shared memory); labels stay raw
        if reference_fn is not None:
            s_raw = S[:k_eval].copy()  # (k, P, B, obs)
        S[...] = obs_norm.apply(S)
        if not has.all():
            S[:, ~has] = 0.0
    fit_cpu = 0.0  # CPU seconds of gradient steps run elsewhere (here: counted by the caller's process)
    noise_seeds = seeds.astype(np.uint64)  # (P,) each member's parameter-noise stream (with cfg.noise > 0)
    if not fit_elsewhere:
        theta_star, before, after, own_before, own_after, _ = fit_rows(
            FitTask(spec, th, S, A, has, cfg.steps, cfg.optimizer, cfg.lr, k_eval, noise=cfg.noise,
                    noise_seeds=noise_seeds))
    else:  # chunks of members elsewhere (each member's steps are independent: the same theta*)
        chunks = [c for c in np.array_split(np.arange(P), map_chunks) if c.size]
        def rows(c: np.ndarray) -> dict:  # a chunk's rows: a handle to shared memory, or a copy
            if ref is not None:
                return dict(S=None, A=None, rows=ref, members=(int(c[0]), int(c[-1]) + 1))
            return dict(S=S[:, c], A=A[:, c])

        outs = map_fit(fit_rows, [FitTask(spec, th[c], has=has[c], steps=cfg.steps, optimizer=cfg.optimizer,
                                          lr=cfg.lr, k_eval=k_eval, noise=cfg.noise, noise_seeds=noise_seeds[c],
                                          **rows(c)) for c in chunks])
        theta_star = np.concatenate([o[0] for o in outs])
        before, after, own_before, own_after = (np.concatenate([o[j] for o in outs]) for j in range(1, 5))
        fit_cpu = float(sum(o[5] for o in outs))
    s_eval = S[:k_eval].transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)  # (k, P, B, obs) -> (P, kB, obs)
    a_eval = A[:k_eval].transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)  # (P, kB, act)
    used = A[:, has].reshape(-1, spec.act_dim)  # (draws * P' * B, act)
    if s_raw is not None:
        s_eval = s_raw.transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)  # (P, kB, obs) raw
    ref = None
    if reference_fn is not None and has.any():
        r = np.asarray(reference_fn(s_eval[has]), np.float32)  # (P', kB, act)
        d_lab = np.linalg.norm(a_eval[has] - r, axis=-1)  # (P', kB)
        d_own = np.linalg.norm(own_before[has] - r, axis=-1)
        d_cln = np.linalg.norm(own_after[has] - r, axis=-1)
        ref = {"label_ref_error": float(d_lab.mean()), "own_ref_error": float(d_own.mean()),
               "clone_ref_error": float(d_cln.mean()), "label_beats_own": float((d_lab < d_own).mean())}
    return CloneResult(theta_star=theta_star, loss_before=before, loss_after=after, samples=n_i,
                       label_std=float(used.std(axis=0).mean()) if used.size else 0.0, reference=ref,
                       fit_cpu_time_s=fit_cpu)


def _label_std(labels: Sequence[np.ndarray]) -> float:
    lab = [x for x in labels if len(x)]
    return float(np.concatenate(lab).std(axis=0).mean()) if lab else 0.0
