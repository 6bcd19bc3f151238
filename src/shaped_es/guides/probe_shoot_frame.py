"""Which frame the shooting labels predict paths in (``shaping.inverse_dynamics.shoot_frame`` auto): the label
probe's choice, by how well each frame's model predicts steps it did not train on.

Why. The shooting labels' chunk model predicts a held action's path from the state (``shaping/forward_shoot.py``).
A body that observes itself only relative to itself has no world heading in its state, so its world-frame path
is not a function of what the model sees; in the waypoint frame (x toward the waypoint) it is. Measured on random
linear policies' steps (16 episodes a body, 4-step paths; fraction of the paths' variance unexplained on 16 more):
CarNav-v0 2.31 (world) against 0.53 (waypoint), a new user's car-and-trailer 1.45 against 0.12; the 16 other
suite and held-out bodies tried predict better in the world frame (0.01-0.55 against 0.16-0.95; UR5Reach-v0 1.39
against 1.56). On the probe's own data (2 generations of 16 policies around the initial mean and babbling; each
frame's model fitted on one generation, scored on the other, both ways) the errors are noisier: the egocentric
bodies' world frame is at 0.95-2.9 (the trailer, CarNav-v0, and egocentric versions of the unicycle, the rover
and the kart, seeds 0-9: ``docs/benchmarks/ego_shoot_v32``) with their waypoint frame at 0.4-1.35, while every
other body's world frame is below 1 on most seeds (up to 1.38 on UR5Reach-v0, 1.37 on a bicycle, whose waypoint
frames are then no better: 0.81-2.1 of it). So the probe takes the waypoint frame where the world frame's model
explains (nearly) nothing, an error of at least :data:`WORLD_FAILS` (the mean path's is 1; the trailer's lowest
0.95), and the waypoint frame's error is at most :data:`RATIO` of it: on the bodies measured, every seed of the
egocentric ones but 5 of 50 (their waypoint frame no clearly better there) and, of the others, one seed of a
boat's (1.02 against 0.77). Deciding by prediction error costs four model fits, no rollouts: simulating both
frames' candidates would double the probe's shooting rollouts.
"""

from __future__ import annotations

from shaped_es.data import Transitions
from shaped_es.guides.clone_probe import cross_fitted
from shaped_es.shaping.forward_shoot import shoot_model

WORLD_FAILS = 0.9  # the world frame's held-out error at which its model explains nothing (at most a tenth)
RATIO = 0.8  # and the waypoint frame's must be at most this share of it


def choose(obs_dim: int, pos_dim: int, act_dim: int, data: list[list[Transitions]], mphi_cfg,
           horizon: int) -> tuple[str, dict[str, float]]:
    """``(frame, {frame: held-out error})``: each frame's chunk model fitted on one generation of ``data`` (a list
    of members' steps per generation) as a run fits it and scored on the others', averaged over the generations;
    ``waypoint`` where the world frame's model explains nothing (error at least :data:`WORLD_FAILS`) and the
    waypoint frame's error is at most :data:`RATIO` of it; else ``world``, also where either cannot be scored
    (one coordinate, one data generation, no paths)."""
    if pos_dim < 2 or len(data) < 2:
        return "world", {}
    errors: dict[str, float] = {}
    for frame in ("world", "waypoint"):
        e = cross_fitted(lambda: shoot_model(obs_dim, pos_dim, act_dim, mphi_cfg, horizon, frame=frame), data,
                         lambda m, trs: m.unexplained(trs))
        if e is None:
            return "world", {}
        errors[frame] = e
    fails = errors["world"] >= WORLD_FAILS and errors["waypoint"] <= RATIO * errors["world"]
    return ("waypoint" if fails else "world"), errors


def decide(mp, spec, pos_dim: int, data: list[list[Transitions]], mphi_cfg) -> tuple[str, dict[str, float]]:
    """The probe's shooting frame for a run whose ``shaping.inverse_dynamics`` section is ``mp``: the configured
    one, else (auto) :func:`choose`'s at ``mp.shoot_horizon`` (the rollout model: the world frame, its only one)."""
    if mp.shoot_frame != "auto":
        return mp.shoot_frame, {}
    if mp.shoot_model != "chunk":
        return "world", {}
    return choose(spec.obs_dim, pos_dim, spec.act_dim, data, mphi_cfg, mp.shoot_horizon)
