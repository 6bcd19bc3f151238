"""The label probe's second question: what would the candidate be with these labels?

The shaped method's labels pay only through the mean's clone (the candidate). A label-driven return
(``label_probe.drive``) ranks what labels do when they steer the body step by step, which is not what a
policy that sees no waypoint can fit: on Unicycle-v0 M_phi's labels drive the body like its controller
yet flip between forward and reverse where the waypoint passes behind, and the mean's clone cannot fit
that; on UR5Reach-v0 ``world``'s labels drive the arm better than ``both``'s and the runs that used them
were slower. So the probe also simulates the candidate of the run's first generations, per variant:

    theta_0 = x0 (the run's initial mean);  D = the probe's recorded steps
    for r in 1..ROUNDS:   theta_r = clone of theta_{r-1} toward the variant's labels on D
                                    (mean_clone's steps, lr, batch size: the run's own clone, fitted plainly)
                          drive theta_r on the probe's seeds, recording its steps; D += them (DAgger)

and reports the last round's per-episode returns (the same seeds for every variant, so variants compare
paired). The probe runs every variant's rounds in lock-step (:func:`clone_rounds_many`). Written by hand:
the clone's Adam steps are the run's compiled kernel (``population_fit``).
"""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.config import RunConfig
from shaped_es.data import Transitions, concat_members
from shaped_es.policies import MLPSpec, ObsNorm, ObsStats
from shaped_es.rollout import run_task
from shaped_es.rollout.task import population_tasks
from shaped_es.shaping.forward_shoot import ShootLabels, shoot_model
from shaped_es.shaping.labels import LabelSource
from shaped_es.shaping.population_fit import FitTask, fit_rows

ROUNDS = 3  # DAgger rounds of the simulated candidate
CLONE_KEY = 1_000_013  # seed key of the simulated clones' minibatch draws
DURING = "the label probe, before generation 1"  # where its rollouts' error lines say they were


def _labelled(trs: list[Transitions], labels: LabelSource) -> tuple[np.ndarray, np.ndarray]:
    """``(states (N, obs), labels (N, act))`` float32 of the members' steps ``trs`` (none: empty)."""
    trs = [t for t in trs if len(t)]
    if not trs:
        return np.zeros((0, 0), np.float32), np.zeros((0, 0), np.float32)
    big = concat_members(trs)[0]  # all rows, (N, ...)
    return big.state.astype(np.float32), np.asarray(labels(big.state, labels.inputs(big)), np.float32)


def first_norm(cfg: RunConfig, spec: MLPSpec) -> ObsNorm | None:
    """The input normalization the probe's data rollouts see (``es.obs_norm``: the statistics of no observation
    yet, so observations clipped to the normalizer's range; None: off). Its simulated candidates then see
    :func:`probe_stats`' normalizer, which generation 0 starts from."""
    return ObsStats.empty(spec.obs_dim).norm() if cfg.es.obs_norm else None


def probe_stats(cfg: RunConfig, data: list[Transitions]) -> ObsStats | None:
    """With ``es.obs_norm``: the observation statistics of the probe's recorded steps (``data``: a member per
    entry), which the run's running statistics start from (None: off). The probe's simulated candidates are
    fitted and driven under their normalizer, so the candidate generation 0 judges and takes sees at generation 1
    nearly the inputs it was fitted on: from an empty normalizer, generation 1's (the first generation's
    statistics) rescaled every input and a new user's probe candidate that won at generation 0 (-9.26) tested at
    -54.91 a generation later."""
    if not cfg.es.obs_norm:
        return None
    rows = [np.asarray(t.state, np.float64) for t in data if len(t)]
    if not rows:
        return None
    S = np.concatenate(rows)  # (N, obs) every recorded observation
    return ObsStats.from_sums(float(len(S)), S.sum(axis=0), (S * S).sum(axis=0))


def roll_out(cfg: RunConfig, spec: MLPSpec, params: np.ndarray, seeds: np.ndarray, generation: int,
             executor=None, norm: ObsNorm | None = None) -> tuple[np.ndarray, np.ndarray, list[Transitions]]:
    """``params`` ``(m, n)`` on episode seeds ``(m, E)``, recorded: ``(returns (m, E), lengths (m, E), one
    Transitions per member)``, in member order. With the run's ``executor``, as its training rollouts are (one
    task of consecutive members per worker); else in this process. A member's numbers do not depend on
    which task it ran in. The policies see ``norm``'s inputs (None: :func:`first_norm`'s)."""
    workers = executor.workers if executor is not None else 1
    tasks = population_tasks(cfg.env, dict(cfg.env_kwargs), spec, np.asarray(params, np.float32),
                             np.asarray(seeds, np.int64), workers, generation, True, cfg.rollout.max_steps,
                             obs_norm=norm if norm is not None else first_norm(cfg, spec))
    for t in tasks:  # its errors name the probe, not a generation number of its seed streams
        t.during = DURING
    results = executor.map(run_task, tasks) if executor is not None else [run_task(t) for t in tasks]
    returns = np.concatenate([np.asarray(r.returns, np.float64) for r in results])  # (m, E)
    lengths = np.concatenate([np.asarray(r.lengths) for r in results])  # (m, E)
    return returns, lengths, [t for r in results for t in r.transitions]


def clone_rounds(cfg: RunConfig, spec: MLPSpec, x0: np.ndarray, data: list[Transitions], labels: LabelSource,
                 seeds: np.ndarray, key: int) -> tuple[np.ndarray, int]:
    """The last round's returns ``(E,)`` of the simulated candidate (module docstring) and the env steps
    its rounds took. ``data``: the probe's recorded steps (a member per entry); ``labels``: the variant's
    label source (a row's label depends on its own episode only, so each round labels just the clone's
    new steps); ``key`` tells variants' minibatch streams apart."""
    return clone_rounds_many(cfg, spec, x0, data, [labels], seeds, [key])[0]


def clone_rounds_many(cfg: RunConfig, spec: MLPSpec, x0: np.ndarray, data: list[Transitions],
                      labels: list[LabelSource], seeds: np.ndarray, keys: list[int],
                      executor=None, thetas: list | None = None, keep: int = 0,
                      protect: tuple[int, ...] = (), on_round=None,
                      norm: ObsNorm | None = None) -> list[tuple[np.ndarray, int]]:
    """:func:`clone_rounds` of several label sources in lock-step, each with its own ``keys[v]``: per round
    one compiled fit of every variant's clone and one batched rollout of them all (the probe's rollouts
    are 10 episodes a variant, where a batched env's per-step overhead dominates), on the run's
    ``executor``'s workers if given (:func:`roll_out`). Every variant's numbers are its own run's: the fit's
    rows and the env's episodes do not interact. ``thetas``: a list that gets each variant's simulated
    candidate ``(n,)`` float32, the policy whose returns are returned (the last round's clone). ``on_round``
    (round index -> None): called after each round's rollouts (the probe's progress lines). ``norm``: the
    normalizer the clones are fitted and driven under (None: :func:`first_norm`'s; ``es.obs_norm``).

    ``keep`` > 0 (successive halving): after the first round only the ``keep`` variants with the best mean
    return, and those in ``protect``, go on; a variant cut there returns its first round's returns, steps and
    clone (the survivors' numbers are what they are without the cut: variants do not interact)."""
    mc, V = cfg.shaping.mean_clone, len(labels)
    norm = norm if norm is not None else first_norm(cfg, spec)  # the clone fits pi(norm(s)) ~ label(s), as the
    #                                                               run's mean clone does
    theta = np.repeat(np.asarray(x0, np.float32)[None], V, axis=0)  # (V, n)
    S_all, A_all = zip(*[_labelled(data, lab) for lab in labels])  # per variant (N_v, obs), (N_v, act)
    S_all, A_all = list(S_all), list(A_all)
    seeds = np.asarray(seeds, np.int64)  # (E,)
    rets, steps = np.zeros((V, len(seeds))), np.zeros(V, np.int64)
    live = list(range(V))  # the variants still in the rounds
    for r in range(ROUNDS):
        if r == 1 and 0 < keep < V:
            ranked = sorted(range(V), key=lambda v: (-float(np.mean(rets[v])), v))
            live = sorted(set(ranked[:keep]) | {int(p) for p in protect})
        fit = [v for v in live if len(S_all[v])] if mc.steps > 0 else []
        if fit:
            S = np.empty((mc.steps, len(fit), mc.batch_size, spec.obs_dim), np.float32)  # (steps, V', B, obs)
            A = np.empty((mc.steps, len(fit), mc.batch_size, spec.act_dim), np.float32)  # (steps, V', B, act)
            for i, v in enumerate(fit):
                rng = np.random.default_rng(seeding.derive_seed(cfg.seed, seeding.SHAPING, CLONE_KEY, keys[v], r))
                idx = rng.integers(0, len(S_all[v]), size=(mc.steps, mc.batch_size))  # (steps, B)
                S[:, i], A[:, i] = S_all[v][idx] if norm is None else norm.apply(S_all[v][idx]), A_all[v][idx]
            # a plain fit, whatever mean_clone.noise: three rounds from the initial mean are too few steps for a
            # fit under parameter noise (CarNav-v0: the generation-0 jump lost; docs/benchmarks/clone_noise_v28)
            theta[fit] = fit_rows(FitTask(spec, theta[fit], S, A, np.ones(len(fit), bool), mc.steps, "adam",
                                          mc.lr, 1))[0]
        r_live, lengths, trs = roll_out(cfg, spec, theta[live], np.repeat(seeds[None], len(live), axis=0),
                                        10_000 + r, executor, norm)  # seeds (E,) -> (V', E); (V', E), one per variant
        rets[live] = r_live
        steps[live] += lengths.sum(axis=1)
        for i, v in enumerate(live):
            s_new, a_new = _labelled(trs[i:i + 1], labels[v])
            if len(s_new):
                S_all[v] = np.concatenate([S_all[v], s_new]) if len(S_all[v]) else s_new  # (N + N', obs)
                A_all[v] = np.concatenate([A_all[v], a_new]) if len(A_all[v]) else a_new  # (N + N', act)
        if on_round is not None:
            on_round(r)
    if thetas is not None:
        thetas.extend(theta[v].copy() for v in range(V))
    return [(rets[v], int(steps[v])) for v in range(V)]


def fit_on(model, data):
    """``model`` (an M_phi, a forward model) fitted on the label probe's data as a run fits it: each probe
    generation's recorded steps (``data``: a list of them) added, then one ``train()``, in turn; returns it."""
    for trs in data:
        model.add(trs)
        model.train()
    return model


def cross_fitted(make, data, error) -> float | None:
    """The label probe's held-out error of a kind of model: ``make()`` fitted (:func:`fit_on`) on each of its data
    generations (``data``: a list of members' steps per generation) in turn and scored by ``error(model, steps)``
    on the other generations' steps, averaged; None where any fit cannot be scored (``error`` None)."""
    scores = []
    for k in range(len(data)):  # cross-fitted: each generation's model scored on the others' steps
        e = error(fit_on(make(), data[k:k + 1]), [t for j, g in enumerate(data) if j != k for t in g])
        if e is None:
            return None
        scores.append(e)
    return float(np.mean(scores))


def shoot_labels(cfg: RunConfig, spec: MLPSpec, data, pos_dim: int, mphi_cfg, horizon: int | None = None,
                 frame: str = "world"):
    """The shooting labels (``shaping/forward_shoot.py``) trained on the label probe's data (``data``: its
    recorded steps per generation); ``horizon``: the steps an action is held (None: the config's); ``frame``:
    their model's."""
    h = horizon or cfg.shaping.inverse_dynamics.shoot_horizon
    kind = cfg.shaping.inverse_dynamics.shoot_model
    m = fit_on(shoot_model(spec.obs_dim, pos_dim, spec.act_dim, mphi_cfg, h, kind=kind, frame=frame), data)
    mp = cfg.shaping.inverse_dynamics
    return ShootLabels(m, mp.shoot_ahead, mp.shoot_cost, mp.shoot_hold)
