"""Evaluate parameter vectors on an environment: returns, step counts and (optionally) transitions.

One :class:`RolloutTask` is a chunk of population members, each run for ``E`` episodes (the paper
evaluates every member on 2 seeds and uses the mean return). All ``m * E`` episodes of a task run in
lock-step with one batched policy forward per step:

- envs with a batched core (``env.unwrapped.batch_core``, see ``envs/core.py``) step all episodes in one
  vectorized call;
- any other Gymnasium env is stepped one instance per episode (the policy forward is still batched).

Actions come out of the policy in ``[-1, 1]``; Box spaces are rescaled to their bounds (which must be
finite: an unbounded Box is refused before the first rollout), Discrete spaces take the argmax, MultiDiscrete an
argmax per sub-action, MultiBinary a bit per positive output (``shaped_es/actions.py``). An env
without a time limit, with ``rollout.max_steps`` unset, has its episodes cut at :data:`DEFAULT_MAX_STEPS`
(with a warning before the first rollout), so an env that never terminates cannot hang a run. Results
depend only on the task's parameters and seeds, never on the process running it. Making and probing an
env before its first rollout lives in ``env_probe.py`` (its names are re-exported here).

Recording (``RolloutTask.record``: every member, or a mask of them) keeps each recorded member's steps as
:class:`~shaped_es.data.Transitions`, sent back as one block per task (``RolloutResult.packed``, a
:class:`~shaped_es.data.PackedTransitions`; ``RolloutResult.transitions`` unpacks it into per-member
views); with ``RolloutTask.expert`` the env's scripted waypoint controller (``envs/core.py``) is asked at
every recorded step too, and its action kept as ``Transitions.expert``, mapped to the policy's
``[-1, 1]`` scale (``actions.from_space``: Box, the inverse of the rescaling above; a choice, +1 for the chosen
option and -1 elsewhere).

Here: which loop runs a task (:func:`run_task`, :func:`run_tasks`) and the episode cap of an endless env.
``task.py`` what a rollout is given and gives back; ``batched.py`` the lock-step loop of a batched core;
``gym_loop.py`` the loops of any other env (lock-step, or one episode after another); ``record.py`` the
recorded steps as one block and the waypoint controller; ``actions.py`` the policy's outputs as the env's
actions; ``checks.py`` an env's output checked; ``obs_sums.py`` the observation sums of ``es.obs_norm``;
``worker_envs.py`` a worker's cached envs and the env's faults as one error.
"""

from __future__ import annotations

import time
import warnings

import numpy as np

from shaped_es.env_probe import (  # noqa: F401 - re-exported: the env's side of a rollout
    EnvError,
    EnvProbe,
    EnvSpecError,
    close_env,
    env_dims,
    env_time_limit,
    exception_line,
    flat_observations,
    flattened_from,
    make_env,
    policy_spec,
    probe_dims,
    probe_env,
)
from shaped_es.envs.core import get_batch_core, runs_serially
from shaped_es.actions import _to_env_action, to_space  # noqa: F401 - re-exported
from shaped_es.rollout.batched import _run_batched, _run_batched_groups
from shaped_es.rollout.gym_loop import _run_gym, _run_serial
from shaped_es.rollout.record import _Recorder  # noqa: F401 - re-exported
from shaped_es.rollout.task import (  # noqa: F401 - re-exported: what a rollout is given and gives back
    RolloutResult,
    RolloutTask,
    mean_returns,
    policy_episode_tasks,
    population_tasks,
)
from shaped_es.rollout.worker_envs import _env_faults, _envs

# Episodes of an env without a time limit (no registered ``max_episode_steps``, no ``TimeLimit``), with
# ``rollout.max_steps`` unset, end here: an env that never terminates would hang the run.
DEFAULT_MAX_STEPS = 10_000


class EnvWarning(UserWarning):
    """Something about the env a run should know before its first rollout (printed as one line)."""


def warn_if_unseeded(env_id: str, probe: EnvProbe) -> None:
    """Say, before the first rollout, that an env whose reset ignores its seed does not reproduce
    (``EnvProbe.unseeded``, probed where the method reads the reset info)."""
    if probe.unseeded:
        warnings.warn(f"env {env_id!r}: reset(seed=0) twice gave different observations: it ignores the seed or "
                      f"carries state from one episode to the next (a NormalizeObservation wrapper), so this run will "
                      f"not reproduce and a generation's members do not face the same episodes (draw every random "
                      f"number from self.np_random after super().reset(seed=seed), reset all state in reset, and "
                      f"normalize observations with --set es.obs_norm=true rather than a wrapper; check-env's seeding "
                      f"line)", EnvWarning, stacklevel=2)


def warn_if_endless(env_id: str, probe: EnvProbe, max_steps: int | None) -> None:
    """Say, before the first rollout, that an env without a time limit has its episodes cut at
    :data:`DEFAULT_MAX_STEPS` (``max_steps``: the run's ``rollout.max_steps``)."""
    if max_steps is None and probe.time_limit is None:
        warnings.warn(f"env {env_id!r} has no time limit and rollout.max_steps is unset: its episodes are "
                      f"cut at {DEFAULT_MAX_STEPS:,} steps (set rollout.max_steps, or register the env with "
                      f"max_episode_steps)", EnvWarning, stacklevel=2)


def run_task(task: RolloutTask) -> RolloutResult:
    """Evaluate every member of ``task`` on its seeds (the worker-side entry point)."""
    t_cpu = time.process_time()
    with _env_faults(task, task.seeds):
        env0 = _envs(task.env_id, task.env_kwargs, 1)[0]
        core = get_batch_core(env0)
        if core is not None:
            out = _run_batched(core, task)
        elif runs_serially(env0):
            out = _run_serial(task, DEFAULT_MAX_STEPS)
        else:
            out = _run_gym(task, DEFAULT_MAX_STEPS)
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
