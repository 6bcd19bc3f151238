"""The lock-step loop of an env with a batched core (``env.unwrapped.batch_core``, ``envs/core.py``):
every episode of one or several tasks stepped in one vectorized call a step.
"""

from __future__ import annotations

import itertools

import numpy as np

from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY
from shaped_es.policies import forward
from shaped_es.rollout.checks import _bad_output
from shaped_es.rollout.obs_sums import _ObsSums
from shaped_es.rollout.record import _controller, _Recorder
from shaped_es.rollout.task import RolloutResult, RolloutTask, _finish, _policy_input


def _run_batched(core, task: RolloutTask) -> RolloutResult:
    return _run_batched_groups(core, [task])[0]


def _run_batched_groups(core, tasks: list[RolloutTask]) -> list[RolloutResult]:
    """The episodes of several tasks (same env and step limit: :func:`fusable`) in one lock-step loop: one
    ``core.reset`` and one ``core.step`` a step for all, one policy forward per task on its own episodes
    (the shapes a lone run of the task uses, so its results are the lone run's, bit for bit: the core's
    episodes are independent copies, ``envs/core.py``). An episode that ended keeps stepping, unread,
    until every episode has, as inside one task."""
    task0 = tasks[0]
    sizes = [t.seeds.size for t in tasks]  # B_i = m_i * E_i episodes of each task
    bounds = np.concatenate([[0], np.cumsum(sizes)])  # (groups + 1,)
    groups = [slice(int(a), int(b)) for a, b in itertools.pairwise(bounds)]  # each task's columns
    B = int(bounds[-1])
    seeds = np.concatenate([t.seeds.reshape(-1) for t in tasks])  # (m_i, E_i) each -> (B,)
    state, obs, info = core.reset(seeds)
    limit = core.max_steps if task0.max_steps is None else min(core.max_steps, task0.max_steps)
    returns = np.zeros(B, dtype=np.float64)
    lengths = np.zeros(B, dtype=np.int64)
    alive = np.ones(B, dtype=bool)
    recs = [_Recorder(t, limit) if t.recorded().any() else None for t in tasks]
    sums = [_ObsSums(sl.stop - sl.start) if t.obs_stats else None for t, sl in zip(tasks, groups)]
    expert = None
    if any(r is not None and t.expert for r, t in zip(recs, tasks)):
        expert = _controller(task0, core)
    for _ in range(limit):
        acts = []
        for t, sl, su in zip(tasks, groups, sums):
            m, E = t.seeds.shape
            if su is not None:
                su.add(obs[sl], alive[sl])
            acts.append(forward(t.spec, t.params, _policy_input(t, obs[sl]).reshape(m, E, -1),
                                t.rowwise).reshape(m * E, -1))  # (m,E,a) -> (B_i,a)
        act = acts[0] if len(acts) == 1 else np.concatenate(acts)  # (B, a)
        pos, wp = info[POSITION_KEY], info[WAYPOINT_KEY]
        ex = None if expert is None else expert(state, obs, info)  # (B, a) before the step, as act
        state, nobs, rew, term, trunc, info = core.step(state, act)
        rew = np.where(alive, rew, 0.0)
        for t, sl, rec in zip(tasks, groups, recs):
            if rec is not None:
                rec.add(obs[sl], pos[sl], wp[sl], act[sl], rew[sl], alive[sl],
                        None if ex is None or not t.expert else ex[sl])
        with np.errstate(over="ignore"):  # a return that overflows is reported below, in one line
            returns += rew
        lengths += alive
        alive &= ~(term | trunc)
        if nobs.shape != obs.shape:
            raise _bad_output(task0, f"observations of shape {nobs.shape} after {obs.shape}", seeds[0],
                              int(lengths.max()))
        obs = nobs
        if not alive.any():
            break
    # Non-finite values persist in the sums, so one check per task covers every step (the loop stays lean)
    bad = ~np.isfinite(returns)
    if bad.any():
        b = int(np.flatnonzero(bad)[0])
        raise _bad_output(task0, "a non-finite reward, or rewards whose sum overflows (inf/NaN)", seeds[b],
                          int(lengths[b]))
    if not np.isfinite(obs).all():
        b = int(np.flatnonzero(~np.isfinite(obs.reshape(B, -1)).all(axis=1))[0])
        raise _bad_output(task0, "a non-finite observation (inf/NaN)", seeds[b], int(lengths[b]))
    return [_finish(t, returns[sl], lengths[sl], rec, su) for t, sl, rec, su in zip(tasks, groups, recs, sums)]
