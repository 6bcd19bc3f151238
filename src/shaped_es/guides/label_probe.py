"""M_phi's frame and query clip chosen by driving the body with its own labels (``frame: auto``).

Which displacement frame makes M_phi's labels useful depends on the body, and no one setting holds on all
of them. Measured closed loop (M_phi's labels ``a_t = M_phi(s_t, q_t)`` driving the env, 20 episodes,
``docs/shaped-results.md``): ``both`` (world + motion frame) drives CarNav-v0 to 162 where ``world`` stays
at -33, while on the torque-driven ReacherWay-v0 ``both`` scores -53, far below zero torque's -10.8, and
``world`` with the query clipped to twice the mean training step scores -7.5 (its controller: -5.7). On
a second-order arm a one-step displacement is mostly the velocity, so motion-frame training inputs sit
near ``(|v|, 0)`` and a waypoint query lands far outside them.

So before the first generation a shaped run with ``frame: auto`` probes: it rolls out :data:`GENERATIONS`
generations' worth of motor babbling and members around the initial mean (as the run's first generations
would; about 0.7 of a default generation's episodes), trains one M_phi per frame on them (``world`` alone in a
1-D waypoint space: ``probe_variants.probe_frames``; there the probe still chooses the clip, the targets, the
shooting horizon and generation 0's candidate), and drives :data:`EPISODES` episodes with each variant's
labels and with zero action, on the same seeds, and simulates each variant's candidate
(``guides/clone_probe.py``: the initial mean cloned toward its labels, 3 DAgger rounds, driven on the
same seeds). The default (``both``, the query as asked) is kept unless

1. another variant's simulated candidate beats the default's (a one-sided signed-rank test of the paired
   episodes at p < 0.05, and a mean gain of at least 5% of the spread of the probe's returns); then the
   one that beats it by the most replaces it; or
2. zero action drives the body better than the default's labels, by more than two standard errors of
   the paired per-episode differences; then the variant whose labels beat the default's by the most.

The candidate, not the labels, is what a shaped run gains by: on Unicycle-v0 every variant's labels drive
the body about as well as its controller, yet ``both``'s flip between forward and reverse where the
waypoint passes behind, and the clone fitted to them crashes on some episodes where the clipped query's
clone does not; on PointForce-v0 ``world``'s clone drives the point where ``both``'s does not. A
label-driven return alone misleads: on UR5Reach-v0 ``world``'s labels drive the arm better than
``both``'s (47.6 against 12.9, 6 seeds) and the runs that used them were slower (4 seeds;
``docs/shaped-results.md``), so labels alone replace the default only where they fail outright, as
``both``'s do on the Reacher.

Each variant is also probed with M_phi trained on chunk targets (``probe_chunk``, 4 steps: ``(s_t, p_{t+4} -
p_t) -> mean(a_t .. a_{t+3})``; ``both+chunk4+clip2``) when the run's targets are one-step. On a differential
drive whose position moves along the heading it had before the step (``pos += v dt (cos th, sin th)``, then
``th += w dt``: how a user writes it), the turn rate never shows in a one-step displacement and a one-step M_phi
has no label for it. A chunk variant is taken only where the frame's test picks it, its simulated candidate
is the best of every variant's and shooting horizon's, *and* the one-step variant chosen without it does not
drive the body better with its labels (two paired standard errors): on the kart the chunk variants beat
``both``'s clearly while the shooting candidate drove far better, and the runs that took them anyway were
slower; on UR5Reach-v0's seeds 0 and 1 the one-step labels drove the arm clearly better and the runs that took
chunk targets ended 19-38 return lower. Measured (``docs/benchmarks/probe_chunk_v15``): a new user's
differential drive, 20 seeds, 8.8 -> 7.3 generations (Vanilla-ES 10.8); on the suite they are taken on
UR5Reach-v0 (3 seeds), the Reacher (2) and the swimmer (2). The chunk variants' simulated candidates have
seed streams of their own, so every other number the probe measures is what it was without them.

With ``rival_shoot`` on, the probe also simulates the candidate of the shooting labels
(``shaping/forward_shoot.py``: the held action whose predicted path passes nearest the waypoint) and keeps
that rival for the run only where its candidate drives the body better than zero action, by two paired
standard errors (``ProbeResult.shoot_on``; ``guides/rival.py``): on the Reacher and the swimmer it drives
worse, and a rival that never wins still adds a lucky row to each generation's pick. It simulates that
candidate holding actions ``shoot_horizon`` steps and each of ``shoot_probe_horizons``, and takes the one
that beats the default's by the frame's test (``ProbeResult.shoot_horizon``; a drone steered by its tilt rate
moves toward the waypoint only after 8-16 steps, ``docs/benchmarks/shoot_horizon_v8``; a sliding hovercraft
after 32, ``docs/benchmarks/probe_horizon32_v20``). Where the probe cannot judge, the rival runs at three of the
probed horizons (``ProbeResult.third_horizon``): the chosen one, the one nearest it and the shortest other; where
it can judge and chose the longest probed horizon, the one nearest it runs beside it (``ProbeResult.long_nearest``,
``shoot_long_nearest``: a long hold's early jump can land where shorter labels win).

The best of the simulated candidates (by mean return, over every variant and horizon) is also kept, as
``ProbeResult.candidate`` and ``RUN/label_probe_candidate.npy``: generation 0's candidate
(``guides/probe_candidate.py``).

The recorded rollouts (the probe's data and the simulated candidates) run on the run's executor's workers, as
its training rollouts do; the label-driven episodes and the models' training run here. The simulated
candidates of every variant and horizon run in lock-step (``clone_probe.clone_rounds_many``:
one fit and one batched rollout per DAgger round, each variant's numbers its own run's), which made the
probe 25-40% faster on the cheap bodies than one variant after another (the same results to the last digit
on the suite and two held-out bodies). The probe is seeded by the run's seed, takes 0.8-3 s on the built-in
envs once the shaping kernels are compiled (the first run after an install compiles them: a few seconds
more; SciPy's statistics, ~0.8 s to import, load with this module, before the clock), and its env steps and wall time
are counted in the run's totals (``env_steps``, ``wall_time_s``) from the first generation on. Its result
is kept in ``RUN/label_probe.json`` (``probe_file.py``) so a resumed run reuses it. ``shaped-es check-env ID
--labels`` runs it for any env.

What it tries and the names it gives each try: ``guides/probe_variants.py``; the rules that choose among
them: ``guides/probe_choice.py``. Its result: ``guides/probe_result.py``;
its episodes (the data, the label-driven episodes, their seeds): ``guides/probe_rollouts.py``; its progress
lines: ``guides/probe_pace.py``. This module runs them in order and chooses.

Written by hand: no library drives an env with an inverse-dynamics model's labels.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from shaped_es import seeding
from shaped_es.config import RunConfig
from shaped_es.policies import MLPSpec
from shaped_es.guides import probe_candidate, probe_shoot_frame, probe_step_change
from shaped_es.guides.clone_probe import clone_rounds_many, fit_on, probe_stats, shoot_labels
from shaped_es.guides.probe_choice import (beats, best_beating, choose_targets,  # noqa: F401 - beats: re-exported
                                          clone_beats, keep_shoot)
from shaped_es.guides.probe_pace import SAY_AFTER_S, Pace  # noqa: F401 - SAY_AFTER_S: re-exported
from shaped_es.guides.probe_result import ProbeResult, not_passed
from shaped_es.guides.probe_rollouts import (  # noqa: F401 - EPISODES, PROBE_KEY, query: re-exported
    BABBLERS, EPISODES, GENERATIONS, MEMBERS, PROBE_KEY, collect, drive, probe_seeds, query, zero_labels)
from shaped_es.guides.probe_variants import long_variants, probe_frames, variant_name, variants
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import MphiLabels
from shaped_es.shaping.settings import InverseDynamicsConfig

LONG_KEY = 200  # the probe_clip_long variants' simulated candidates' seed keys (the others' are as without them)
CHUNK_KEY = 100  # the chunk variants' simulated candidates' seed keys start here (the others' are as before them)


def probe(cfg: RunConfig, spec: MLPSpec, pos_dim: int, mphi_cfg: InverseDynamicsConfig,
          executor=None, say=None) -> ProbeResult:
    """Run the probe (module docstring) and return what it chose; its recorded rollouts (the data and the
    simulated candidates) run on ``executor``'s workers if given, the label-driven episodes here. ``say``
    (a line -> None): where a long probe's progress lines go (:class:`Pace`; None: nowhere)."""
    t0 = time.perf_counter()
    pace = Pace(say, t0)
    x0 = seeding.initial_mean(spec, cfg.seed)
    mp = cfg.shaping.inverse_dynamics
    chunk_len = mp.probe_chunk if mphi_cfg.targets == "one_step" else 0
    frames = probe_frames(pos_dim)
    # the variants' count for the progress lines: the same whichever clips the step change decides below
    n_vs = len(variants(mp.query_clip, chunk_len, frames)) + len(long_variants(mp.query_clip, mp.probe_clip_long,
                                                                               chunk_len, frames))
    n_shoot = len(dict.fromkeys((mp.shoot_horizon, *mp.shoot_probe_horizons))) if mp.rival_shoot else 0
    per = (MEMBERS + BABBLERS) * cfg.rollout.episodes  # episodes a probe data generation
    data, steps = collect(cfg, spec, x0, executor, lambda g, n: pace.after_data(
        n, (g + 1) * per, n_vs + 1, n_vs + n_shoot, (GENERATIONS - 1 - g) * per))
    seeds = probe_seeds(cfg)
    returns: dict[str, list[float]] = {}
    clones: dict[str, list[float]] = {}  # the simulated candidate's returns (guides/clone_probe.py)
    models: dict[tuple[str, int | None], tuple[InverseDynamics, float]] = {}
    # M_phi's step_change (auto: by its models' held-out error on the probe's two data generations), for every
    # M_phi the probe fits and the run's (forward models ignore it)
    step_change, change_errors = probe_step_change.decide(mp, spec, pos_dim, data, mphi_cfg)
    mphi_cfg = replace(mphi_cfg, step_change=step_change)
    # a second-order body: the incumbent clips the query to the mean training step (probe_variants.clips)
    base = variants(mp.query_clip, chunk_len, frames, step_change)
    vs = base + long_variants(mp.query_clip, mp.probe_clip_long, chunk_len, frames)
    flat = [t for g in data for t in g]  # the probe's recorded steps, a member per entry
    stats = probe_stats(cfg, flat)  # es.obs_norm: generation 0's statistics, its candidates' normalizer (None: off)
    sources = []  # each variant's label source, in order (their simulated candidates run in lock-step below)
    for frame, clip, chunk in vs:
        if (frame, chunk) not in models:
            mc = replace(mphi_cfg, frame=frame, **({} if chunk is None else {"targets": "chunk", "horizon": chunk}))
            m = fit_on(InverseDynamics(spec.obs_dim, pos_dim, spec.act_dim, mc), data)
            x = m.newest(m.dataset_size)[0][:, spec.obs_dim: spec.obs_dim + m.displacement_dim]  # (N, d')
            models[(frame, chunk)] = (m, float(np.linalg.norm(x, axis=1).mean()) if len(x) else 0.0)
        m, step = models[(frame, chunk)]
        label = MphiLabels(m, frame, mphi_cfg.query_scale, mphi_cfg.query_mix)  # the run's own label source
        label.max_displacement = None if clip is None or step == 0 else clip * step
        r, n = drive(cfg, label, frame, seeds, mphi_cfg.query_mix)
        returns[variant_name(frame, clip, chunk)] = [float(v) for v in r]
        steps += n
        sources.append(label)
    zero, n = drive(cfg, zero_labels(spec.act_dim), "world", seeds)
    steps += n
    shoot, shoot_on, horizon, tried = [], None, None, {}
    # the shooting rival is kept only where its clone drives, at the horizon that drives best
    horizons = list(dict.fromkeys((mp.shoot_horizon, *mp.shoot_probe_horizons))) if mp.rival_shoot else []
    # a longer hold than the probe's longest episode has no row to learn from (a 20-step body's 32-step model
    # would be its initial weights): not probed
    longest = max((int(np.bincount(t.episode).max()) for t in flat if len(t)), default=0)  # steps
    horizons = [h for h in horizons if h == mp.shoot_horizon or h < longest]
    shoot_frame, frame_errors = probe_shoot_frame.decide(mp, spec, pos_dim, data, mphi_cfg) if horizons else (None, {})
    shooters = [shoot_labels(cfg, spec, data, pos_dim, mphi_cfg, h, shoot_frame or "world") for h in horizons]
    thetas: list[np.ndarray] = []  # each simulated candidate (n,), in the order of sources + shooters
    one = sum(v[2] is None for v in base)  # the one-step variants: keys 0.., the shooters' next (as before chunks)
    keys = ([i if v[2] is None else CHUNK_KEY + i for i, v in enumerate(base)]
            + [LONG_KEY + j for j in range(len(vs) - len(base))] + list(range(one, one + len(horizons))))
    # the default variant (0) runs every round: the others are judged against it
    sims = clone_rounds_many(cfg, spec, x0, flat, sources + shooters, seeds, keys, executor, thetas, mp.probe_keep,
                             (0,), on_round=pace.after_round, norm=None if stats is None else stats.norm())
    for (frame, clip, chunk), (r, n) in zip(vs, sims):
        clones[variant_name(frame, clip, chunk)] = [float(v) for v in r]
        steps += n
    for h, (r, n) in zip(horizons, sims[len(vs):]):
        tried[str(h)], steps = [float(v) for v in r], steps + n
    simulated = {**clones, **{f"shoot:{h}": v for h, v in tried.items()}}  # every simulated candidate's returns
    by_name = dict(zip([variant_name(*v) for v in vs] + [f"shoot:{h}" for h in horizons], thetas))
    long_tag = f"+clip{mp.probe_clip_long:g}" if len(vs) > len(base) else None
    name, reason = choose_targets({k: np.array(v) for k, v in returns.items()}, variant_name(*vs[0]), zero,
                                  {k: np.array(v) for k, v in clones.items()},
                                  probe_candidate.rank(simulated, by_name), long_tag)
    frame, clip, chunk = next(v for v in vs if variant_name(*v) == name)
    # the extensions passed over: generation 0's candidate and the shooting rival's test are decided without
    # their clones (a variant the run does not use neither keeps nor drops a rival it does use; a new user's
    # quadrotor: a passed-over chunk variant's clone beat zero action and so dropped the shooting rival)
    passed = [t for t in ("+chunk", long_tag) if t and t not in name]
    standing = {k: np.array(v) for k, v in not_passed(clones, passed).items()}
    if horizons:
        seen = np.concatenate([np.ravel(v) for v in (*returns.values(), *clones.values(), *tried.values(), zero)])
        scale = float(seen.max() - seen.min())
        best, _ = best_beating({k: np.array(v) for k, v in tried.items()}, str(mp.shoot_horizon),
                                lambda a, b: clone_beats(a, b, scale))
        horizon, shoot = int(best), tried[best]
        shoot_on = keep_shoot(np.array(shoot), zero, standing, mp.shoot_keep_best, mp.shoot_unjudged,
                              {k: np.array(v) for k, v in tried.items()})
    top = probe_candidate.best(not_passed(simulated, passed), by_name)
    return ProbeResult(frame, clip, returns, steps, time.perf_counter() - t0, reason, [float(v) for v in zero],
                       clones, shoot, shoot_on, horizon, tried if len(tried) > 1 else {},
                       *(top if top is not None else (None, None)), chunk, passed,
                       None if stats is None else [stats.count, stats.mean.tolist(), stats.m2.tolist()],
                       shoot_frame, frame_errors, step_change, change_errors)
