"""The label probe's second question: what would the candidate be with these labels?

The shaped method's labels pay only through the mean's clone (the candidate). A label-driven return
(``label_probe.drive``) ranks what labels do when they steer the body step by step, which is not what a
policy that sees no waypoint can fit: on Unicycle-v0 M_phi's labels drive the body like its controller
yet flip between forward and reverse where the waypoint passes behind, and the mean's clone cannot fit
that; on UR5Reach-v0 ``world``'s labels drive the arm better than ``both``'s and the runs that used them
were slower. So the probe also simulates the candidate of the run's first generations, per variant:

    theta_0 = x0 (the run's initial mean);  D = the probe's recorded steps
    for r in 1..ROUNDS:   theta_r = clone of theta_{r-1} toward the variant's labels on D
                                    (mean_clone's steps, lr, batch size: the run's own clone)
                          drive theta_r on the probe's seeds, recording its steps; D += them (DAgger)

and reports the last round's per-episode returns (the same seeds for every variant, so variants compare
paired). Written by hand: the clone's Adam steps are the run's compiled kernel (``population_fit``).
"""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.config import RunConfig
from shaped_es.data import Transitions, concat_members
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask, run_task
from shaped_es.shaping.forward_shoot import ShootLabels, shoot_model
from shaped_es.shaping.labels import LabelSource
from shaped_es.shaping.population_fit import FitTask, fit_rows

ROUNDS = 3  # DAgger rounds of the simulated candidate
CLONE_KEY = 1_000_013  # seed key of the simulated clones' minibatch draws


def _labelled(trs: list[Transitions], labels: LabelSource) -> tuple[np.ndarray, np.ndarray]:
    """``(states (N, obs), labels (N, act))`` float32 of the members' steps ``trs`` (none: empty)."""
    trs = [t for t in trs if len(t)]
    if not trs:
        return np.zeros((0, 0), np.float32), np.zeros((0, 0), np.float32)
    big = concat_members(trs)[0]  # all rows, (N, ...)
    return big.state.astype(np.float32), np.asarray(labels(big.state, labels.inputs(big)), np.float32)


def clone_rounds(cfg: RunConfig, spec: MLPSpec, x0: np.ndarray, data: list[Transitions], labels: LabelSource,
                 seeds: np.ndarray, key: int) -> tuple[np.ndarray, int]:
    """The last round's returns ``(E,)`` of the simulated candidate (module docstring) and the env steps
    its rounds took. ``data``: the probe's recorded steps (a member per entry); ``labels``: the variant's
    label source (a row's label depends on its own episode only, so each round labels just the clone's
    new steps); ``key`` tells variants' minibatch streams apart."""
    mc = cfg.shaping.mean_clone
    theta = np.asarray(x0, np.float32)[None].copy()  # (1, n)
    S_all, A_all = _labelled(data, labels)  # (N, obs), (N, act)
    rets, steps = np.zeros(len(seeds)), 0
    for r in range(ROUNDS):
        if len(S_all) and mc.steps > 0:
            rng = np.random.default_rng(seeding.derive_seed(cfg.seed, seeding.SHAPING, CLONE_KEY, key, r))
            idx = rng.integers(0, len(S_all), size=(mc.steps, mc.batch_size))  # (steps, B)
            S = S_all[idx][:, None]  # (steps, B, obs) -> (steps, 1, B, obs)
            A = A_all[idx][:, None]  # (steps, 1, B, act)
            theta = fit_rows(FitTask(spec, theta, S, A, np.ones(1, bool), mc.steps, "adam", mc.lr, 1))[0]
        res = run_task(RolloutTask(cfg.env, dict(cfg.env_kwargs), spec, theta.astype(np.float32), np.arange(1),
                                   np.asarray(seeds, np.int64)[None], generation=10_000 + r, record=True,
                                   max_steps=cfg.rollout.max_steps))  # seeds (E,) -> (1, E)
        rets = np.asarray(res.returns, np.float64).reshape(-1)  # (1, E) -> (E,)
        steps += int(res.lengths.sum())
        s_new, a_new = _labelled(res.transitions, labels)
        if len(s_new):
            S_all = np.concatenate([S_all, s_new]) if len(S_all) else s_new  # (N + N', obs)
            A_all = np.concatenate([A_all, a_new]) if len(A_all) else a_new  # (N + N', act)
    return rets, steps


def shoot_clone(cfg: RunConfig, spec: MLPSpec, x0: np.ndarray, data, pos_dim: int, mphi_cfg, seeds: np.ndarray,
                key: int, horizon: int | None = None) -> tuple[np.ndarray, int]:
    """The shooting labels' simulated candidate (:func:`clone_rounds`) on the label probe's data (``data``:
    its recorded steps per generation): its returns ``(E,)`` and env steps. On ReacherWay-v0 and
    SwimmerWay-v0 it drives worse than zero action (their gaits and whipping arms are no held action's
    path), where its candidate only adds a lucky row to each generation's pick; on the planar bodies far
    better (``docs/benchmarks/suite_bodies_v7``). ``horizon``: the steps an action is held (None: the config's)."""
    h = horizon or cfg.shaping.inverse_dynamics.shoot_horizon
    m = shoot_model(spec.obs_dim, pos_dim, spec.act_dim, mphi_cfg, h)
    for trs in data:
        m.add(trs)
        m.train()
    labels = ShootLabels(m, cfg.shaping.inverse_dynamics.shoot_ahead)
    return clone_rounds(cfg, spec, x0, [t for g in data for t in g], labels, seeds, key)
