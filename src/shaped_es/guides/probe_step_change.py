"""Whether M_phi also sees a step's change from the last one (``shaping.inverse_dynamics.step_change`` auto): the
label probe's choice, by how well M_phi with and without it predicts actions it did not train on.

Why. On a second-order body a one-step displacement is mostly the velocity the body already had, and the action
shows only in a small departure from it: M_phi must learn the action as the difference of two nearly equal inputs
(``shaping/mphi_inputs.change_block``). A new user's spacecraft attitude body (torque -> rate -> angle): M_phi's
held-out action R^2 0.14 after the probe's 1000 Adam steps, 0.97 with the change as an input; its labels drove the
body to 15-22 instead of 8, and the runs reached a return of 15 in 6.6 generations instead of 15.0 (10 seeds,
``docs/benchmarks/step_change_v33``). On the suite, forced on everywhere, no task's generations to its threshold
moved clearly either way, but UR5Reach-v0's late reward was 5 lower in the point estimate: so the probe takes it
only where M_phi without it explains little of the held-out actions (error at least :data:`PLAIN_FAILS`) and with
it at most :data:`RATIO` of that. Each model is fitted on one of the probe's two data generations as the run fits
it and scored on the other's steps, both ways (cross-fitted); four fits, no rollouts.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from shaped_es.data import Transitions
from shaped_es.guides.clone_probe import cross_fitted
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.mphi_inputs import target_pairs

PLAIN_FAILS = 0.3  # M_phi's held-out action error (unexplained share of the actions' variance) worth improving
RATIO = 0.5  # and the error with the change must be at most this share of it


def unexplained(m: InverseDynamics, trs: list[Transitions]) -> float | None:
    """The share of the actions' variance M_phi's labels of the steps ``trs`` (their own displacements) leave
    unexplained (None: no step to score)."""
    pairs = [target_pairs(t, m.config.frame, step_change=m.step_change) for t in trs if len(t) > 1]
    if not pairs:
        return None
    s, d, a = (np.concatenate(x) for x in zip(*pairs))  # (N, obs), (N, d'), (N, act)
    var = float(((a - a.mean(0)) ** 2).sum())
    if not len(a) or var <= 0:
        return None
    return float(((m.label(s, d) - a) ** 2).sum()) / var


def choose(obs_dim: int, pos_dim: int, act_dim: int, data: list[list[Transitions]], mphi_cfg
           ) -> tuple[bool, dict[str, float]]:
    """``(on, {"plain": error, "change": error})``: each world-frame one-step M_phi fitted on one generation of
    ``data`` (the members' steps per generation) and scored on the others', averaged; on where the plain model's
    error is at least :data:`PLAIN_FAILS` and the change's at most :data:`RATIO` of it; off where either cannot
    be scored (one data generation, no steps)."""
    if len(data) < 2:
        return False, {}
    errors: dict[str, float] = {}
    for name, flag in (("plain", False), ("change", True)):
        cfg = replace(mphi_cfg, frame="world", targets="one_step", step_change=flag)
        e = cross_fitted(lambda: InverseDynamics(obs_dim, pos_dim, act_dim, cfg), data,
                         lambda m, trs: unexplained(m, trs) if m.iterations else None)  # an untrained fit: no score
        if e is None:
            return False, {}
        errors[name] = e
    return bool(errors["plain"] >= PLAIN_FAILS and errors["change"] <= RATIO * errors["plain"]), errors


def decide(mp, spec, pos_dim: int, data: list[list[Transitions]], mphi_cfg) -> tuple[bool, dict[str, float]]:
    """The probe's ``step_change`` for a run whose ``shaping.inverse_dynamics`` section is ``mp``: the configured
    one (true, false), else (auto) :func:`choose`'s."""
    if mp.step_change != "auto":
        return bool(mp.step_change), {}
    return choose(spec.obs_dim, pos_dim, spec.act_dim, data, mphi_cfg)
