"""The loops of an env without a batched core: one Gymnasium env per episode, stepped in lock-step with one
batched policy forward a step (``_run_gym``), or, for an env whose instances in a process share one
simulator (``envs.core.runs_serially``), its episodes one after another (``_run_serial``).
"""

from __future__ import annotations

from dataclasses import replace

import gymnasium as gym
import numpy as np

from shaped_es.data import pack
from shaped_es.env_probe import OLD_STEP, BadOutput, env_time_limit, exception_line, observation, old_api, \
    reset_output, reward, step_output
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY
from shaped_es.policies import forward
from shaped_es.actions import action_map, action_problem, action_text, from_space
from shaped_es.rollout.checks import _bad_controller, _bad_output, _check_obs, _check_pairs, _contract
from shaped_es.rollout.obs_sums import _ObsSums, _sum_in_order
from shaped_es.rollout.periodic import Unwrapper, period_of
from shaped_es.rollout.record import _controller, _join_episodes, _Recorder
from shaped_es.rollout.task import RolloutResult, RolloutTask, _finish, _policy_input
from shaped_es.rollout.worker_envs import _envs, tag_seed


# Positions whose magnitude passes this (UTM coordinates, a large map) are recorded from the episode's first
# position: float32 keeps about 7 digits, so at 4e6 m a 0.1 m step rounds away, and M_phi's displacements with
# it (a new user's point at a UTM offset: labels driving to -34.5 against -12.4 at the origin). Every use of the
# recorded pairs is a difference within an episode (a displacement, w - p), which the shift leaves as it was;
# below FAR nothing is shifted, so those rollouts record what they always did, bit for bit.
FAR = 1e3


def _reset(task: RolloutTask, env: gym.Env, seed: int) -> tuple:
    try:
        return reset_output(env.reset(seed=seed))
    except BadOutput as exc:
        raise _bad_output(task, str(exc), seed, 0) from None
    except (Exception, SystemExit) as exc:  # the env's own: its line names this episode's seed
        tag_seed(exc, seed)
        raise


def _step(env: gym.Env, action) -> tuple:
    """``env.step``: ``(obs, reward, terminated, truncated, info)`` checked (``env_probe.step_output``)."""
    try:
        out = env.step(action)
    except ValueError as exc:
        if old_api(exc):  # Gymnasium's TimeLimit unpacking the env's 4-tuple
            raise BadOutput(OLD_STEP) from None
        raise
    return step_output(out)


def _controller_action(task: RolloutTask, space: gym.Space, hook, obs, info, seed, step: int) -> np.ndarray:
    """The controller's action for ``(obs, info)`` on the policy's ``[-1, 1]`` scale, ``(act,)``; one error naming
    the controller where it raises or returns no action of ``space`` (a gear out of range would else become
    another option's label, silently)."""
    try:
        a = hook(obs, info)
    except Exception as exc:  # noqa: BLE001 - the env's own code: one line naming it
        raise _bad_controller(task, f"raised {exception_line(exc)}", seed, step) from None
    problem = action_problem(space, a)
    if problem:
        raise _bad_controller(task, f"returned {action_text(a)}, not an action of {space} ({problem})", seed, step)
    return from_space(space, a)


def _run_serial(task: RolloutTask, default_cap: int) -> RolloutResult:
    """The episodes of ``task`` one after another on one env (an env whose instances in a process share
    one simulator, ``envs.core.runs_serially``), giving what the lock-step run gives: returns and
    lengths ``(m, E)``, and per member one :class:`Transitions` of its E episodes in episode order
    (``default_cap``: as :func:`_run_gym`'s)."""
    m, E = task.seeds.shape
    rec = task.recorded()  # (m,)
    parts = [[_run_gym(replace(task, params=task.params[i:i + 1], members=task.members[i:i + 1],
                               seeds=task.seeds[i:i + 1, e:e + 1], record=bool(rec[i])), default_cap)
              for e in range(E)] for i in range(m)]
    transitions = []
    for i, row in enumerate(parts):
        eps = [(e, p.transitions[0]) for e, p in enumerate(row) if p.transitions]
        if eps:
            transitions.append(_join_episodes(task.generation, int(task.members[i]), eps))
    stats = None
    if task.obs_stats:  # each member's episodes summed in episode order, as _ObsSums.per_member sums them
        stats = tuple(np.stack([_sum_in_order([p.obs_stats[k][0] for p in row]) for row in parts])
                      for k in range(3))  # (m,), (m, obs), (m, obs)
    return RolloutResult(members=np.asarray(task.members), cpu_time_s=0.0, obs_stats=stats,
                         packed=pack(transitions) if transitions else None,
                         returns=np.array([[p.returns[0, 0] for p in row] for row in parts]),  # (m, E)
                         lengths=np.array([[p.lengths[0, 0] for p in row] for row in parts]))


def _run_gym(task: RolloutTask, default_cap: int) -> RolloutResult:
    """The episodes of ``task``, one env each, in lock-step; ``default_cap``: where the episodes of an env
    without a time limit end when ``task.max_steps`` is unset (``rollout.DEFAULT_MAX_STEPS``)."""
    m, E = task.seeds.shape
    B = m * E
    envs = _envs(task.env_id, task.env_kwargs, B)
    seeds = task.seeds.reshape(B)  # (m, E) -> (B,)
    first = [_reset(task, env, int(s)) for env, s in zip(envs, seeds)]
    infos = [i for _, i in first]  # the latest info of each env (the waypoint controller reads it)
    shape = tuple(envs[0].observation_space.shape)
    obs = np.zeros((B, *shape), np.float32)  # (B, obs)
    for b, (o, _) in enumerate(first):
        try:
            obs[b] = _check_obs(task, observation(o, shape), shape, seeds[b], 0)
        except BadOutput as exc:
            raise _bad_output(task, str(exc), seeds[b], 0) from None
    rec = _Recorder(task) if task.recorded().any() else None
    # the waypoint contract, checked where it is used: recorded steps (the shaped method's data) of an env
    # whose reset info has it (without it: no columns, d = 0; the shaped method's preflight refuses that)
    pos, wp = np.zeros((B, 0), np.float32), np.zeros((B, 0), np.float32)  # (B, d)
    contract = rec is not None and (POSITION_KEY in infos[0] or WAYPOINT_KEY in infos[0])
    origin = None  # (B, d) float64: where the pairs are recorded from (far from 0 only; see FAR)
    unwrap = None  # a position that wraps (a heading): recorded continuous, w - p the short way (periodic.py)
    if contract:
        d = _contract(task, infos[0], None, seeds[0], 0)[0].size  # every episode's pair of this size
        pairs = [_contract(task, i, d, seeds[b], 0, dtype=np.float64) for b, i in enumerate(infos)]
        pos, wp = np.stack([p for p, _ in pairs]), np.stack([w for _, w in pairs])  # (B, d) float64
        late = task.position_period  # found in the run's own rows after its start (RolloutTask)
        period = late if late is not None and len(late) == d else period_of(envs[0], task.env_id, task.env_kwargs, d)
        if period is not None:
            unwrap = Unwrapper(period)
            pos, wp = unwrap.start(pos, wp)
        far = np.maximum(np.abs(pos), np.abs(wp)).max(axis=1) > FAR  # (B,)
        if far.any():
            origin = np.where(far[:, None], pos, 0.0)  # (B, d) each far episode's first position
            pos, wp = pos - origin, wp - origin
        pos, wp = pos.astype(np.float32), wp.astype(np.float32)
    returns = np.zeros(B, dtype=np.float64)
    lengths = np.zeros(B, dtype=np.int64)
    alive = np.ones(B, dtype=bool)
    sums = _ObsSums(B) if task.obs_stats else None
    hooks = [_controller(task, env.unwrapped) for env in envs] if rec is not None and task.expert else None
    to_env = [action_map(env.action_space) for env in envs]  # (B,) each env's policy output -> its action
    cap = task.max_steps
    if cap is None and env_time_limit(envs[0]) is None:
        cap = default_cap  # an env that never terminates cannot hang the run (warn_if_endless)
    t = 0
    while alive.any() and (cap is None or t < cap):
        if sums is not None:
            sums.add(obs, alive)
        act = forward(task.spec, task.params, _policy_input(task, obs).reshape(m, E, -1),
                      task.rowwise).reshape(B, -1)  # (m,E,a) -> (B,a)
        ex = None
        if hooks is not None:  # (B, a): the controller's action where the episode runs, else zeros
            ex = np.zeros_like(act)
            for b in np.flatnonzero(alive):
                ex[b] = _controller_action(task, envs[b].action_space, hooks[b], obs[b], infos[b], seeds[b], t)
        rew = np.zeros(B, dtype=np.float64)
        nobs, npos, nwp = obs.copy(), pos.copy(), wp.copy()
        stepped = alive.copy()
        for b in np.flatnonzero(stepped):
            try:
                o, r, term, trunc, info = _step(envs[b], to_env[b](act[b]))
                o, r = observation(o, shape), reward(r)
            except BadOutput as exc:
                raise _bad_output(task, str(exc), seeds[b], t + 1) from None
            except (Exception, SystemExit) as exc:  # the env's own: its line names this episode's seed
                tag_seed(exc, seeds[b])
                raise
            if o.shape != shape:
                _check_obs(task, o, shape, seeds[b], t + 1)
            nobs[b], rew[b], infos[b] = o, r, info
            if contract and origin is None and unwrap is None:  # finite: checked below, every env's at once
                npos[b], nwp[b] = _contract(task, info, pos.shape[1], seeds[b], t + 1, finite=False)
            elif contract:  # unwrapped and/or from the episode's origin, in float64 (then float32, as recorded)
                p, w = _contract(task, info, pos.shape[1], seeds[b], t + 1, finite=False, dtype=np.float64)
                if unwrap is not None:
                    p, w = unwrap.step(b, p, w)
                npos[b], nwp[b] = (p, w) if origin is None else (p - origin[b], w - origin[b])
            alive[b] = not (term or trunc)
        if not (np.isfinite(rew).all() and np.isfinite(nobs).all()):  # one check per step, all envs
            b = int(np.flatnonzero(~(np.isfinite(rew) & np.isfinite(nobs).all(axis=1)))[0])
            if not np.isfinite(rew[b]):
                raise _bad_output(task, f"a non-finite reward ({rew[b]})", seeds[b], t + 1)
            _check_obs(task, nobs[b], shape, seeds[b], t + 1)
        if contract:
            _check_pairs(task, npos, nwp, infos, seeds, t + 1)
        if rec is not None:
            rec.add(obs, pos, wp, act, rew, stepped, ex)
        with np.errstate(over="ignore"):  # a return that overflows is reported below, in one line
            returns += rew
        lengths += stepped
        obs, pos, wp = nobs, npos, nwp
        t += 1
    if not np.isfinite(returns).all():  # finite rewards (checked each step) whose sum overflowed
        b = int(np.flatnonzero(~np.isfinite(returns))[0])
        raise _bad_output(task, f"rewards whose sum overflows (the episode return reached {returns[b]}; "
                          f"rewards must stay far below 1e308)", seeds[b], int(lengths[b]))
    return _finish(task, returns, lengths, rec, sums)
