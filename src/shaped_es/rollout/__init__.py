"""Evaluate parameter vectors on an environment: returns, step counts and (optionally) transitions.

One :class:`RolloutTask` is a chunk of population members, each run for ``E`` episodes (the paper
evaluates every member on 2 seeds and uses the mean return). All ``m * E`` episodes of a task run in
lock-step with one batched policy forward per step:

- envs with a batched core (``env.unwrapped.batch_core``, see ``envs/core.py``) step all episodes in one
  vectorized call;
- any other Gymnasium env is stepped one instance per episode (the policy forward is still batched).

Actions come out of the policy in ``[-1, 1]``; Box spaces are rescaled to their bounds (which must be
finite: an unbounded Box is refused before the first rollout), Discrete spaces take the argmax. An env
without a time limit, with ``rollout.max_steps`` unset, has its episodes cut at :data:`DEFAULT_MAX_STEPS`
(with a warning before the first rollout), so an env that never terminates cannot hang a run. Results
depend only on the task's parameters and seeds, never on the process running it. Making and probing an
env before its first rollout lives in ``env_probe.py`` (its names are re-exported here).

Recording (``RolloutTask.record``: every member, or a mask of them) keeps each recorded member's steps as
:class:`~shaped_es.data.Transitions`, sent back as one block per task (``RolloutResult.packed``, a
:class:`~shaped_es.data.PackedTransitions`; ``RolloutResult.transitions`` unpacks it into per-member
views); with ``RolloutTask.expert`` the env's scripted waypoint controller (``envs/core.py``) is asked at
every recorded step too, and its action kept as ``Transitions.expert``, mapped to the policy's
``[-1, 1]`` scale (Box: the inverse of the rescaling above; Discrete: +1 for the chosen action, -1
elsewhere). The recording itself (the step buffers, the one block, the controller) lives in
``rollout/record.py``; the loops that step the envs live here.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import time
import traceback
import warnings
from dataclasses import dataclass, replace

import gymnasium as gym
import numpy as np

from shaped_es.data import PackedTransitions, Transitions, pack
from shaped_es.env_probe import (  # noqa: F401 - re-exported: the env's side of a rollout
    EnvError,
    EnvProbe,
    EnvSpecError,
    close_env,
    env_dims,
    env_time_limit,
    exception_line,
    make_env,
    policy_spec,
    probe_dims,
    probe_env,
)
from shaped_es.env_probe import OLD_STEP, BadOutput, observation, old_api, reset_output, reward, step_output, \
    waypoint_pair
from shaped_es.envs.core import POSITION_KEY, WAYPOINT_KEY, get_batch_core, runs_serially
from shaped_es.policies import MLPSpec, ObsNorm, forward
from shaped_es.rollout.record import _controller, _from_env_action, _join_episodes, _Recorder

# Episodes of an env without a time limit (no registered ``max_episode_steps``, no ``TimeLimit``), with
# ``rollout.max_steps`` unset, end here: an env that never terminates would hang the run.
DEFAULT_MAX_STEPS = 10_000


class EnvWarning(UserWarning):
    """Something about the env a run should know before its first rollout (printed as one line)."""




@dataclass
class RolloutTask:
    """A chunk of members to evaluate. Picklable (crosses process boundaries as a task, never to disk)."""

    env_id: str
    env_kwargs: dict
    spec: MLPSpec
    params: np.ndarray  # (m, n) float32, one row per member
    members: np.ndarray  # (m,) int, population index of each row
    seeds: np.ndarray  # (m, E) int64, episode seeds
    generation: int = 0
    # keep per-step transitions (for the inverse-dynamics model): every member, or a mask (m,) of them
    record: bool | np.ndarray = False
    max_steps: int | None = None  # cap on episode length (None: the env's own limit)
    expert: bool = False  # also record the env's waypoint controller's action (envs/core.py hook)
    rowwise: bool = False  # each observation's action on its own, bit for bit (policies.forward; evaluate)
    obs_norm: ObsNorm | None = None  # the policies' input normalization (es.obs_norm), applied before forward
    obs_stats: bool = False  # also return each member's observation count, sum and sum of squares

    def recorded(self) -> np.ndarray:
        """Mask ``(m,)`` of the members whose transitions are kept."""
        m = self.params.shape[0]
        if isinstance(self.record, (bool, np.bool_)):
            return np.full(m, bool(self.record))
        mask = np.asarray(self.record, dtype=bool).reshape(-1)
        if mask.shape != (m,):
            raise ValueError(f"record mask has {mask.shape[0]} entries for {m} members")
        return mask


@dataclass
class RolloutResult:
    members: np.ndarray  # (m,)
    returns: np.ndarray  # (m, E) float64, cumulative reward per episode
    lengths: np.ndarray  # (m, E) int64, steps per episode
    cpu_time_s: float  # CPU seconds this task used in its process
    # the recorded members' steps as one block (None: nothing recorded); one object to pickle, not one
    # per member (``transitions`` unpacks it into per-member views)
    packed: PackedTransitions | None = None
    # RolloutTask.obs_stats: per member, the raw observations its policy saw (alive steps, float32 values
    # summed in float64): count (m,), sum (m, obs), sum of squares (m, obs); the master merges them in
    # member order, so the statistics do not depend on how members were split into tasks
    obs_stats: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None

    @property
    def transitions(self) -> list[Transitions]:
        """One :class:`Transitions` per recorded member (views of :attr:`packed`; ``[]`` without)."""
        return [] if self.packed is None else self.packed.unpack()

    @transitions.setter
    def transitions(self, trs: list[Transitions]) -> None:
        self.packed = pack(list(trs)) if len(trs) else None


def mean_returns(results: list[RolloutResult]) -> np.ndarray:
    """Each member's mean return, ``(m,)`` in member order, from results whose returns are ``(m_i, E_i)``
    (a guide's extra members may run more episodes than the population)."""
    return np.concatenate([np.asarray(r.returns).mean(axis=1) for r in results])


def population_tasks(env_id: str, env_kwargs: dict, spec: MLPSpec, params: np.ndarray, seeds: np.ndarray,
                     workers: int, generation: int = 0, record: bool | np.ndarray = False,
                     max_steps: int | None = None, expert: bool = False, obs_norm: ObsNorm | None = None,
                     obs_stats: bool = False) -> list[RolloutTask]:
    """A population ``params`` ``(P, n)`` on its episode seeds ``(P, E)``, as at most ``workers`` tasks of
    consecutive members (training rollouts); ``record``: every member, or a mask ``(P,)``; ``obs_norm``:
    the members' input normalization; ``obs_stats``: return their observations' sums."""
    members = np.arange(params.shape[0])
    rec = record if isinstance(record, (bool, np.bool_)) else np.asarray(record, dtype=bool).reshape(-1)
    return [RolloutTask(env_id, env_kwargs, spec, params[idx], members[idx], seeds[idx], generation=generation,
                        record=rec if isinstance(rec, (bool, np.bool_)) else rec[idx], max_steps=max_steps,
                        expert=expert, obs_norm=obs_norm, obs_stats=obs_stats)
            for idx in np.array_split(members, max(1, min(len(members), workers)))]


def policy_episode_tasks(env_id: str, env_kwargs: dict, spec: MLPSpec, theta: np.ndarray,
                         seeds: np.ndarray, workers: int, generation: int = 0,
                         max_steps: int | None = None, rowwise: bool = False,
                         obs_norm: ObsNorm | None = None) -> list[RolloutTask]:
    """One policy ``theta`` ``(n,)`` on episode seeds ``(E,)``, split into at most ``workers`` tasks
    (test and evaluation episodes; each task is "member 0" of its own chunk of seeds); ``rowwise``:
    ``evaluate``'s episodes, whose actions equal ``load_policy(...).predict``'s bit for bit; ``obs_norm``:
    the policy's input normalization."""
    seeds = np.asarray(seeds).reshape(1, -1)  # (1, E)
    E = seeds.shape[1]
    return [RolloutTask(env_id, env_kwargs, spec, theta[None], np.zeros(1, int), seeds[:, c],
                        generation=generation, max_steps=max_steps, rowwise=rowwise, obs_norm=obs_norm)
            for c in np.array_split(np.arange(E), max(1, min(E, workers)))]


_ENV_CACHE: dict[str, list[gym.Env]] = {}


def _env_key(env_id: str, env_kwargs: dict) -> str:
    return env_id + json.dumps(env_kwargs, sort_keys=True, default=str)


def warn_if_endless(env_id: str, probe: EnvProbe, max_steps: int | None) -> None:
    """Say, before the first rollout, that an env without a time limit has its episodes cut at
    :data:`DEFAULT_MAX_STEPS` (``max_steps``: the run's ``rollout.max_steps``)."""
    if max_steps is None and probe.time_limit is None:
        warnings.warn(f"env {env_id!r} has no time limit and rollout.max_steps is unset: its episodes are "
                      f"cut at {DEFAULT_MAX_STEPS:,} steps (set rollout.max_steps, or register the env with "
                      f"max_episode_steps)", EnvWarning, stacklevel=2)


def _envs(env_id: str, env_kwargs: dict, count: int) -> list[gym.Env]:
    key = _env_key(env_id, env_kwargs)
    envs = _ENV_CACHE.setdefault(key, [])
    while len(envs) < count:
        envs.append(make_env(env_id, env_kwargs))
    return envs[:count]


def to_space(space: gym.Space, a: np.ndarray) -> np.ndarray:
    """Policy outputs ``(..., act)`` in ``[-1, 1]`` -> actions of ``space``: ``(...,)`` int64 for Discrete
    (the argmax), ``(..., act)`` for Box, rescaled to its bounds as ``centre + half_width * a``, which is
    ``a`` itself, bit for bit, for the ``[-1, 1]`` Box of the built-in envs (whose batched cores take the
    policy's output as it is). Rollouts, ``load_policy(...).predict`` and ``render`` all map actions here."""
    if isinstance(space, gym.spaces.Discrete):
        return np.argmax(a, axis=-1).astype(np.int64) + int(space.start)
    low, high = space.low, space.high
    return ((high + low) * 0.5 + (high - low) * 0.5 * a).astype(space.dtype)


def _to_env_action(space: gym.Space, a: np.ndarray):
    """One policy output ``(act,)`` -> one action of ``space`` (:func:`to_space`)."""
    out = to_space(space, a)
    return int(out) if isinstance(space, gym.spaces.Discrete) else out


def run_task(task: RolloutTask) -> RolloutResult:
    """Evaluate every member of ``task`` on its seeds (the worker-side entry point)."""
    t_cpu = time.process_time()
    with _env_faults(task, task.seeds):
        env0 = _envs(task.env_id, task.env_kwargs, 1)[0]
        core = get_batch_core(env0)
        if core is not None:
            out = _run_batched(core, task)
        elif runs_serially(env0):
            out = _run_serial(task)
        else:
            out = _run_gym(task)
    out.cpu_time_s = time.process_time() - t_cpu
    return out


def fusable(tasks: list[RolloutTask]) -> bool:
    """Whether ``tasks`` can run in one lock-step loop (:func:`run_tasks`): one env, one policy
    architecture and one step limit."""
    t0 = tasks[0]
    return all(t.env_id == t0.env_id and t.env_kwargs == t0.env_kwargs and t.spec == t0.spec
               and t.max_steps == t0.max_steps for t in tasks[1:])


def run_tasks(tasks: list[RolloutTask]) -> list[RolloutResult]:
    """Evaluate several tasks in one call (a worker-side entry point): on an env with a batched core,
    tasks that :func:`fusable` allows run in one lock-step loop, sharing each step's Python overhead,
    which a small task (a guide's few extra members) pays nearly in full on its own; the results are
    :func:`run_task`'s, one per task, bit for bit (tested). Each result's ``cpu_time_s`` is its share,
    by episodes, of the call's."""
    tasks = list(tasks)
    if len(tasks) < 2 or not fusable(tasks):
        return [run_task(t) for t in tasks]
    t_cpu = time.process_time()
    task0 = tasks[0]
    with _env_faults(task0, np.concatenate([t.seeds.reshape(-1) for t in tasks])):
        env0 = _envs(task0.env_id, task0.env_kwargs, 1)[0]
        core = get_batch_core(env0)
        if core is None:
            return [run_task(t) for t in tasks]
        out = _run_batched_groups(core, tasks)
    cpu = time.process_time() - t_cpu
    total = sum(t.seeds.size for t in tasks)
    for r, t in zip(out, tasks):
        r.cpu_time_s = cpu * t.seeds.size / total
    return out


@contextlib.contextmanager
def _env_faults(task: RolloutTask, seeds: np.ndarray):
    """An env's exception or ``sys.exit`` inside the block -> one :class:`EnvError` naming the env, the
    generation and the episode ``seeds``; the cached envs, in an unknown state, are dropped."""
    try:
        yield
    except Exception as exc:
        _ENV_CACHE.pop(_env_key(task.env_id, task.env_kwargs), None)  # envs in an unknown state
        if isinstance(exc, EnvError):
            raise
        raise EnvError(f"env {task.env_id!r} raised {exception_line(exc)} (generation {task.generation}, "
                       f"episode seeds {_seed_text(seeds)})", traceback.format_exc(),
                       worker_fault=bool(getattr(exc, "worker_fault", False))) from None
    except SystemExit as exc:  # would end the command (or the worker) as if the run had finished
        _ENV_CACHE.pop(_env_key(task.env_id, task.env_kwargs), None)
        raise EnvError(f"env {task.env_id!r} called sys.exit({exc.code!r}) during a rollout (generation "
                       f"{task.generation}, episode seeds {_seed_text(seeds)}); an env reports a failure "
                       f"by raising an exception", traceback.format_exc()) from None


def _seed_text(seeds: np.ndarray) -> str:
    flat = list(dict.fromkeys(int(x) for x in np.asarray(seeds).reshape(-1)))  # distinct, in order
    return ", ".join(map(str, flat[:3])) + (", ..." if len(flat) > 3 else "")


def _bad_output(task: RolloutTask, what: str, seed, step: int) -> EnvError:
    return EnvError(f"env {task.env_id!r} returned {what} (generation {task.generation}, episode seed "
                    f"{int(seed)}, step {step}); check the env's step/reset")


def _check_obs(task, obs: np.ndarray, shape: tuple, seed, step: int) -> np.ndarray:
    if obs.shape != shape:
        raise _bad_output(task, f"an observation of shape {obs.shape}, its observation space says {shape}",
                          seed, step)
    if not np.isfinite(obs).all():
        raise _bad_output(task, "a non-finite observation (inf/NaN)", seed, step)
    return obs


def _contract(task, info: dict, d: int | None, seed, step: int) -> tuple[np.ndarray, np.ndarray]:
    """``info``'s position and waypoint (``env_probe.waypoint_pair``), or the error naming the env."""
    try:
        return waypoint_pair(info, d)
    except BadOutput as exc:
        raise _bad_output(task, str(exc), seed, step) from None


def _policy_input(task: RolloutTask, obs: np.ndarray) -> np.ndarray:
    """The observations ``(B, obs)`` as the policies take them (``task.obs_norm`` applied, if any)."""
    return obs if task.obs_norm is None else task.obs_norm.apply(obs)


def _sum_in_order(parts: list[np.ndarray]) -> np.ndarray:
    """``parts[0] + parts[1] + ...`` left to right (the same rounding whatever batch they came from)."""
    acc = np.array(parts[0], dtype=np.float64, copy=True)
    for p in parts[1:]:
        acc = acc + p
    return acc


class _ObsSums:
    """Per episode column: the count, sum and sum of squares (float64) of the observations the policy saw
    while the episode ran (elementwise accumulation over steps, so a column's sums do not depend on the
    batch it ran in)."""

    def __init__(self, B: int):
        self.count = np.zeros(B)  # (B,)
        self.total: np.ndarray | None = None  # (B, obs)
        self.squares: np.ndarray | None = None  # (B, obs)

    def add(self, obs: np.ndarray, alive: np.ndarray) -> None:
        x = np.asarray(obs, dtype=np.float32).astype(np.float64)  # what the policy sees, in float64
        x = np.where(alive[:, None], x, 0.0)  # (B, obs)
        if self.total is None:
            self.total, self.squares = np.zeros_like(x), np.zeros_like(x)
        self.count += alive
        self.total += x
        self.squares += x * x

    def per_member(self, m: int, E: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(count (m,), sum (m, obs), sum of squares (m, obs)): each member's E episodes summed in order."""
        d = 0 if self.total is None else self.total.shape[1]
        total = np.zeros((m * E, d)) if self.total is None else self.total
        squares = np.zeros((m * E, d)) if self.squares is None else self.squares
        return tuple(_sum_in_order([x.reshape(m, E, *x.shape[1:])[:, e] for e in range(E)])
                     for x in (self.count, total, squares))


def _finish(task, returns, lengths, rec, sums=None) -> RolloutResult:
    m, E = task.seeds.shape
    return RolloutResult(obs_stats=None if sums is None else sums.per_member(m, E),
        members=np.asarray(task.members),
        returns=returns.reshape(m, E),  # (m*E,) -> (m, E)
        lengths=lengths.reshape(m, E),
        cpu_time_s=0.0,
        packed=rec.build() if rec is not None else None,
    )


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


def _reset(task: RolloutTask, env: gym.Env, seed: int) -> tuple:
    try:
        return reset_output(env.reset(seed=seed))
    except BadOutput as exc:
        raise _bad_output(task, str(exc), seed, 0) from None


def _step(env: gym.Env, action) -> tuple:
    """``env.step``: ``(obs, reward, terminated, truncated, info)`` checked (``env_probe.step_output``)."""
    try:
        out = env.step(action)
    except ValueError as exc:
        if old_api(exc):  # Gymnasium's TimeLimit unpacking the env's 4-tuple
            raise BadOutput(OLD_STEP) from None
        raise
    return step_output(out)


def _run_serial(task: RolloutTask) -> RolloutResult:
    """The episodes of ``task`` one after another on one env (an env whose instances in a process share
    one simulator, ``envs.core.runs_serially``), giving what the lock-step run gives: returns and
    lengths ``(m, E)``, and per member one :class:`Transitions` of its E episodes in episode order."""
    m, E = task.seeds.shape
    rec = task.recorded()  # (m,)
    parts = [[_run_gym(replace(task, params=task.params[i:i + 1], members=task.members[i:i + 1],
                               seeds=task.seeds[i:i + 1, e:e + 1], record=bool(rec[i])))
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


def _run_gym(task: RolloutTask) -> RolloutResult:
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
    if contract:
        d = _contract(task, infos[0], None, seeds[0], 0)[0].size  # every episode's pair of this size
        pairs = [_contract(task, i, d, seeds[b], 0) for b, i in enumerate(infos)]
        pos, wp = np.stack([p for p, _ in pairs]), np.stack([w for _, w in pairs])
    returns = np.zeros(B, dtype=np.float64)
    lengths = np.zeros(B, dtype=np.int64)
    alive = np.ones(B, dtype=bool)
    sums = _ObsSums(B) if task.obs_stats else None
    hooks = [_controller(task, env.unwrapped) for env in envs] if rec is not None and task.expert else None
    cap = task.max_steps
    if cap is None and env_time_limit(envs[0]) is None:
        cap = DEFAULT_MAX_STEPS  # an env that never terminates cannot hang the run (warn_if_endless)
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
                ex[b] = _from_env_action(envs[b].action_space, hooks[b](obs[b], infos[b]))
        rew = np.zeros(B, dtype=np.float64)
        nobs, npos, nwp = obs.copy(), pos.copy(), wp.copy()
        stepped = alive.copy()
        for b in np.flatnonzero(stepped):
            try:
                o, r, term, trunc, info = _step(envs[b], _to_env_action(envs[b].action_space, act[b]))
                o, r = observation(o, shape), reward(r)
            except BadOutput as exc:
                raise _bad_output(task, str(exc), seeds[b], t + 1) from None
            if o.shape != shape:
                _check_obs(task, o, shape, seeds[b], t + 1)
            nobs[b], rew[b], infos[b] = o, r, info
            if contract:
                npos[b], nwp[b] = _contract(task, info, pos.shape[1], seeds[b], t + 1)
            alive[b] = not (term or trunc)
        if not (np.isfinite(rew).all() and np.isfinite(nobs).all()):  # one check per step, all envs
            b = int(np.flatnonzero(~(np.isfinite(rew) & np.isfinite(nobs).all(axis=1)))[0])
            if not np.isfinite(rew[b]):
                raise _bad_output(task, f"a non-finite reward ({rew[b]})", seeds[b], t + 1)
            _check_obs(task, nobs[b], shape, seeds[b], t + 1)
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
