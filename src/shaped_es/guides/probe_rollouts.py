"""The label probe's episodes (``label_probe.py``): its recorded data, babblers and members around the initial
mean on the run's executor (:func:`collect`), the seeds every variant is driven on (:func:`probe_seeds`), and the
episodes a label source drives here, batched through the env's core where it has one (:func:`drive`; zero action
as a label source: :func:`zero_labels`), asking the labels M_phi's query online as the recorded rollouts have it
(:func:`query`)."""

from __future__ import annotations

import numpy as np

from shaped_es import seeding
from shaped_es.config import RunConfig
from shaped_es.env_probe import reward as one_reward
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY, get_batch_core
from shaped_es.policies import MLPSpec
from shaped_es.rollout import make_env, to_space
from shaped_es.rollout.periodic import Unwrapper, period_of
from shaped_es.shaping.frames import rotate
from shaped_es.guides.clone_probe import roll_out
from shaped_es.shaping.mphi_inputs import mixed_query

GENERATIONS = 2  # generations of probe data (babblers + members around the initial mean)
MEMBERS = 8  # members around the initial mean per probe generation (at es.sigma)
BABBLERS = 8  # babbling policies per probe generation (weights ~ N(0, babble_sigma^2))
EPISODES = 10  # closed-loop episodes per variant (the same seeds for every variant)
PROBE_KEY = 1_000_011  # seed key of the probe's streams


def probe_seeds(cfg: RunConfig) -> np.ndarray:
    """The seeds ``(EPISODES,)`` of the probe's episodes: every variant, zero action and each simulated candidate
    is driven on these (``check-env --labels`` drives zero action on them again)."""
    return np.array([seeding.derive_seed(cfg.seed, seeding.SHAPING, PROBE_KEY, 1000 + e) for e in range(EPISODES)])


def collect(cfg: RunConfig, spec: MLPSpec, x0: np.ndarray, executor=None, on_generation=None):
    """The probe's recorded rollouts: per generation, members around ``x0`` and babblers (on the run's
    ``executor``'s workers if given); returns ``(transitions per generation, env steps)``. ``on_generation``
    ((generation, env steps so far) -> None): called after each (the probe's progress lines)."""
    sigma_b = cfg.shaping.inverse_dynamics.babble_sigma
    out, steps = [], 0
    for g in range(GENERATIONS):
        rng = np.random.default_rng(seeding.derive_seed(cfg.seed, seeding.SHAPING, PROBE_KEY, g))
        near = x0 + cfg.es.sigma * rng.standard_normal((MEMBERS, spec.num_params))  # (MEMBERS, n)
        bab = sigma_b * rng.standard_normal((BABBLERS, spec.num_params))  # (BABBLERS, n)
        P = np.concatenate([near, bab]).astype(np.float32)  # (m, n)
        seeds = rng.integers(0, 2**31 - 1, size=(P.shape[0], cfg.rollout.episodes))  # (m, E)
        _, lengths, trs = roll_out(cfg, spec, P, seeds, g, executor)
        out.append(trs)
        steps += int(lengths.sum())
        if on_generation is not None:
            on_generation(g, steps)
    return out, steps


def query(pos: np.ndarray, wp: np.ndarray, prev: np.ndarray, frame: str, mix: float = 1.0,
          last_too: bool = False) -> np.ndarray:
    """M_phi's query ``(B, d)`` or ``(B, 2d)`` online, as ``query_displacement`` offline: ``w_t - p_t``
    mixed with the last step (``mixed_query``) in ``frame`` (the motion frame: the angle of
    ``p_t - p_{t-1}``, 0 at an episode's first step; the waypoint frame: the angle of ``w_t - p_t``; as
    ``shaping/frames.py``); ``last_too``: the last step ``(B, d)`` after it, as ``query_inputs`` keeps it
    (M_phi's ``step_change``)."""
    if last_too:
        return np.concatenate([query(pos, wp, prev, frame, mix), (pos - prev).astype(np.float32)], axis=1)
    last = (pos - prev).astype(np.float64)  # (B, d) the last step
    toward = (wp - pos).astype(np.float64)  # (B, d)
    d = mixed_query(toward, last, mix)  # (B, d)
    if frame == "world":
        return d.astype(np.float32)
    if frame == "waypoint":  # x toward the waypoint (frames.waypoint_angle)
        return rotate(d, np.arctan2(toward[:, 1], toward[:, 0])).astype(np.float32)
    m = rotate(d, np.arctan2(last[:, 1], last[:, 0]))  # motion frame; angle 0 where the agent did not move
    if frame == "motion":
        return m.astype(np.float32)
    return np.concatenate([d, m], axis=1).astype(np.float32)  # (B, 2d)


def zero_labels(act_dim: int):
    """Zero action (the middle of the action space) as a label source for :func:`drive`: the probe's baseline."""
    return lambda s, q: np.zeros((s.shape[0], act_dim), np.float32)  # (B, act)


def drive(cfg: RunConfig, label, frame: str, seeds: np.ndarray, mix: float = 1.0) -> tuple[np.ndarray, int]:
    """Returns ``(E,)`` of episodes driven by ``label(obs (B, obs), query) -> (B, act)`` and their steps;
    batched through the env's core when it has one, else one Gymnasium env episode by episode."""
    env = make_env(cfg.env, cfg.env_kwargs)  # observations as the run's rollouts see them (flattened)
    last = bool(getattr(label, "last_width", 0))  # M_phi's step_change: the last step follows the query
    try:
        core = get_batch_core(env)
        if core is not None:
            return _drive_core(core, cfg, label, frame, seeds, mix, last)
        rets, steps = [], 0
        pair = lambda info: tuple(np.asarray(info[k], np.float64).reshape(1, -1) for k in (POSITION_KEY, WAYPOINT_KEY))
        for s in seeds:
            obs, info = env.reset(seed=int(s))
            period = period_of(env, cfg.env, cfg.env_kwargs, pair(info)[0].shape[1])
            unwrap = None if period is None else Unwrapper(period)  # as the recorded rollouts (gym_loop)
            pos, wp = pair(info) if unwrap is None else unwrap.start(*pair(info))
            prev = pos
            ret, t = 0.0, 0
            while True:
                a = label(np.asarray(obs, np.float32).reshape(1, -1), query(pos, wp, prev, frame, mix, last))[0]
                obs, r, term, trunc, info = env.step(to_space(env.action_space, np.clip(a, -1, 1)))
                ret, t = ret + one_reward(r), t + 1
                if term or trunc or (cfg.rollout.max_steps is not None and t >= cfg.rollout.max_steps):
                    break
                p, w = pair(info)
                prev, (pos, wp) = pos, ((p, w) if unwrap is None else
                                        tuple(x[None] for x in unwrap.step(0, p[0], w[0])))
            rets.append(ret)
            steps += t
        return np.array(rets), steps
    finally:
        env.close()


def _drive_core(core, cfg: RunConfig, label, frame: str, seeds: np.ndarray, mix: float,
                last: bool = False) -> tuple[np.ndarray, int]:
    state, obs, info = core.reset(np.asarray(seeds, np.int64))
    B = len(seeds)
    limit = core.max_steps if cfg.rollout.max_steps is None else min(core.max_steps, cfg.rollout.max_steps)
    rets, alive, steps = np.zeros(B), np.ones(B, bool), 0
    pos = prev = np.asarray(info[POSITION_KEY], np.float64).reshape(B, -1)  # (B, d)
    for _ in range(limit):
        wp = np.asarray(info[WAYPOINT_KEY], np.float64).reshape(B, -1)
        a = np.clip(label(np.asarray(obs, np.float32).reshape(B, -1), query(pos, wp, prev, frame, mix, last)), -1, 1)
        state, obs, r, term, trunc, info = core.step(state, a.astype(np.float32))
        rets += np.where(alive, r, 0.0)
        steps += int(alive.sum())
        alive &= ~(np.asarray(term) | np.asarray(trunc))
        if not alive.any():
            break
        prev, pos = pos, np.asarray(info[POSITION_KEY], np.float64).reshape(B, -1)
    return rets, steps
