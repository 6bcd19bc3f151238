"""M_phi's inputs: the displacements it is trained on and the ones it is asked for.

``M_phi(s_t, displacement) -> a_t`` (``inverse_dynamics.py``) learns from recorded steps and answers
queries; this module forms both from :class:`~shaped_es.data.Transitions`:

- training triples ``(s_t, position_{t+h} - position_t, a_t)`` (:func:`target_pairs`, the paper's one-step
  pairs :func:`training_pairs`), of the episodes whose return passes the filter (:func:`kept_episodes`);
- queries ``waypoint_t - position_t`` (:func:`query_displacement`), optionally mixed with the last step
  (:func:`mixed_query`) or rescaled to the agent's own pace,

each in M_phi's displacement frame (``frames.py``).
"""

from __future__ import annotations

import numpy as np

from shaped_es.data import Transitions
from shaped_es.shaping.frames import last_step, to_frame
from shaped_es.shaping.settings import QUERY_SCALES, TARGETS


def _run_breaks(tr: Transitions) -> np.ndarray:
    """``(T-1,)``: row ``t+1`` begins a new contiguous episode run (another episode, or a step not following)."""
    return ~((tr.episode[1:] == tr.episode[:-1]) & (tr.step[1:] == tr.step[:-1] + 1))


def _run_last(brk: np.ndarray) -> np.ndarray:
    """``brk`` ``(T-1,)``: row ``t+1`` begins a new run -> row index ``(T,)`` of the last row of each row's run."""
    last = np.flatnonzero(np.append(brk, True))  # (runs,) last row of each run
    return last[np.searchsorted(last, np.arange(len(brk) + 1))]  # (T,)


def episode_end(tr: Transitions) -> np.ndarray:
    """Row index ``(T,)`` of the last step of each row's episode (rows are contiguous per episode)."""
    if len(tr) == 0:
        return np.zeros(0, np.int64)
    return _run_last(_run_breaks(tr))  # (T,)


def waypoint_before(tr: Transitions) -> np.ndarray:
    """The waypoint each row's waypoint took over from, ``(T, d)``: the last different waypoint of its
    episode, or the episode's first position while its first waypoint holds. ``w_t - waypoint_before`` is
    the waypoint path's last step (one spacing of spatial waypoints; a timed schedule's last step)."""
    T = len(tr)
    if T == 0:
        return tr.waypoint.copy()
    idx = np.arange(T)
    start = np.ones(T, bool)  # a contiguous episode run begins here
    start[1:] = _run_breaks(tr)
    change = start.copy()
    change[1:] |= np.any(tr.waypoint[1:] != tr.waypoint[:-1], axis=1)  # (T,) a new waypoint
    since = np.maximum.accumulate(np.where(change, idx, 0))  # (T,) the row its waypoint appeared at
    return np.where(start[since][:, None], tr.position[since], tr.waypoint[np.maximum(since - 1, 0)])


def waypoint_held(tr: Transitions, before: np.ndarray | None = None) -> np.ndarray:
    """``(T,)`` bool: the row's waypoint is a goal the body reached and that stayed -- its episode's last waypoint,
    unchanged from the row to the episode's end, with the body within half the waypoint path's last step
    (``|w_t - waypoint_before|``, :func:`waypoint_before`; ``before`` if already computed) of it at the row or a
    later one. A waypoint that is consumed when reached would have changed there; one that stays is the point to
    hold, which an aim past it (the shooting labels' pure-pursuit look ahead) would overshoot. Known in hindsight
    only: the labels of recorded rows read it."""
    T = len(tr)
    if T == 0:
        return np.zeros(0, bool)
    before = waypoint_before(tr) if before is None else before
    radius = 0.5 * np.linalg.norm(tr.waypoint - before, axis=1)  # (T,)
    near = np.linalg.norm(tr.waypoint - tr.position, axis=1) <= radius  # (T,)
    brk = _run_breaks(tr)  # (T-1,) a new episode run
    end = _run_last(brk)  # (T,) the episode's last row
    stretch_end = _run_last(brk | np.any(tr.waypoint[1:] != tr.waypoint[:-1], axis=1))  # (T,) ... of one waypoint
    next_near = np.minimum.accumulate(np.where(near, np.arange(T), T)[::-1])[::-1]  # (T,) first near row >= t
    return (next_near <= stretch_end) & (stretch_end == end)


def target_pairs(tr: Transitions, frame: str, targets: str = "one_step", horizon: int = 8,
                 rng: np.random.Generator | None = None, step_change: bool = False
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Training triples ``(s_t, position_{t+h} - position_t, a_t)`` for the rows that have a successor.

    - ``one_step`` (paper): ``h = 1``, what one action did;
    - ``hindsight``: ``h ~ U{1..horizon}`` (goal-conditioned relabelling, as GCSL): a displacement the
      agent reached from ``s_t`` in a few steps, labelled with its first action ``a_t``;
    - ``matched``: the smallest ``h <= horizon`` whose displacement reaches the query distance
      ``|waypoint_t - position_t|`` of that state, so training inputs lie where queries do;
    - ``chunk``: ``h = horizon``, labelled with the mean action ``a_t..a_{t+h-1}`` (an action chunk):
      "the action which, held for h steps, moves the agent this far". On a torque-driven body a one-step
      displacement is almost all velocity (ReacherWay-v0 even reads the fingertip one physics substep
      late), so a one-step inverse is ill-posed: MuJoCo's exact one-step inverse, asked for
      ``w_t - p_t``, drives the arm to -91 where zero torque scores -11.5, the exact 6-step held-action
      inverse to -10 (``docs/shaped-results.md``). An option, not a default: offered to the label probe,
      its candidates did not pay in runs (the Reacher and the swimmer unchanged, two UR5 seeds unsolved).

    ``h`` never crosses the end of the episode. Returns ``(T', obs)``, ``(T', d)``, ``(T', act)``; with
    ``step_change`` the displacement has :func:`change_block`'s ``d`` more columns, ``(T', d + d)``.
    """
    end = episode_end(tr)  # (T,)
    idx = np.arange(len(tr))
    room = end - idx  # (T,) steps left in the episode
    rows = room > 0
    if targets == "one_step":
        h = np.ones(len(tr), np.int64)
    elif targets == "hindsight":
        gen = rng if rng is not None else np.random.default_rng(0)
        h = gen.integers(1, horizon + 1, size=len(tr))
    elif targets == "chunk":
        h = np.full(len(tr), horizon, np.int64)
    elif targets == "matched":
        want = np.linalg.norm(tr.waypoint - tr.position, axis=1)  # (T,) query distance
        h = np.full(len(tr), horizon, np.int64)
        found = np.zeros(len(tr), bool)
        for k in range(1, horizon + 1):  # smallest k reaching the query distance
            j = np.minimum(idx + k, end)
            hit = ~found & (np.linalg.norm(tr.position[j] - tr.position, axis=1) >= want)
            h[hit], found = k, found | hit
    else:
        raise ValueError(f"targets must be one of {TARGETS}, got {targets!r}")
    h = np.minimum(h, np.maximum(room, 1))
    world = tr.position[np.minimum(idx + h, end)] - tr.position  # (T, d)
    disp = to_frame(tr, world, frame)  # (T, d')
    if step_change:
        disp = np.concatenate([disp, change_block(world, last_step(tr), h)], axis=1).astype(disp.dtype)  # (T, d' + d)
    if targets != "chunk":
        return tr.state[rows], disp[rows], tr.action[rows]
    csum = np.concatenate([np.zeros((1, tr.action.shape[1])), np.cumsum(tr.action, axis=0, dtype=np.float64)])  # (T+1, act)
    chunk = (csum[np.minimum(idx + h, len(tr))] - csum[idx]) / h[:, None]  # (T, act) mean of a_t..a_{t+h-1}
    return tr.state[rows], disp[rows], chunk[rows].astype(tr.action.dtype)


def clip_norm(d: np.ndarray, max_norm: float | None) -> np.ndarray:
    """Scale rows of ``d`` ``(..., k)`` down to at most ``max_norm`` in Euclidean norm."""
    if max_norm is None:
        return d
    n = np.linalg.norm(d, axis=-1, keepdims=True)  # (..., 1)
    return d * np.minimum(1.0, max_norm / np.maximum(n, 1e-12))


def change_block(world: np.ndarray, last: np.ndarray, h) -> np.ndarray:
    """``world - h * last`` ``(T, d)``: how far a displacement over ``h`` steps (``h``: ``(T,)`` or a number)
    departs from the last step's pace (``step_change``).

    On a second-order body (torque -> acceleration -> velocity -> position) a step is mostly the velocity the
    body already had: on a new user's spacecraft attitude body the torque moves a step by ~15% of what the rate
    does, so M_phi must learn the action as the difference of two nearly equal inputs (the displacement and the
    state's rate), and a (20, 20) network fitted 1000 Adam steps explains 14% of the held-out actions' variance
    (96% after 8000). Given this difference as an input, it explains 97% after 1000 steps, and its labels drive
    that body to 15-22 where the plain fit's drive it to 8 (the exact inverse: 30); PointForce-v0 97% against
    82% after 500 steps, the velocity-driven point and the unicycle unchanged
    (``docs/benchmarks/heldout_attitude_forklift_v33/diag``)."""
    hh = np.asarray(h, np.float64)
    return (np.asarray(world, np.float64) - (hh[:, None] if hh.ndim else hh) * np.asarray(last, np.float64))


def query_change(q: np.ndarray, last: np.ndarray, d: int, h: int = 1) -> np.ndarray:
    """A query ``q`` ``(..., d')`` (the world displacement first: frames ``world``, ``both``) with its
    :func:`change_block` appended, ``(..., d' + d)``: ``last`` ``(..., d)`` the last step ``p_t - p_{t-1}``."""
    q = np.asarray(q)
    return np.concatenate([q, change_block(q[..., :d].reshape(-1, d), last.reshape(-1, d), h)
                           .reshape(*q.shape[:-1], d).astype(q.dtype)], axis=-1)


def kept_episodes(tr: Transitions, min_return: float, filter: str) -> tuple[np.ndarray, np.ndarray]:
    """``(episodes, kept)``: the episode ids of ``tr`` and those passing the filter (Sec. IV: "trajectories
    which do not have a cumulative positive reward of 5 are discarded")."""
    eps, inv = np.unique(tr.episode, return_inverse=True)
    if filter == "none":
        return eps, eps
    r = np.maximum(tr.reward, 0.0) if filter == "positive" else tr.reward
    ret = np.bincount(inv.reshape(-1), weights=r.astype(np.float64), minlength=eps.size)  # (E,) returns
    return eps, eps[ret >= min_return]


def training_pairs(tr: Transitions, frame: str = "world") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(s_t, position_{t+1} - position_t, a_t)`` for every step with a successor in its episode (the
    paper's pairs: :func:`target_pairs` with ``targets="one_step"``)."""
    return target_pairs(tr, frame, "one_step")


def mixed_query(toward: np.ndarray, last: np.ndarray, mix: float) -> np.ndarray:
    """``(1 - mix) * last + mix * toward`` ``(..., d)``: the last step turned a share ``mix`` of the way to
    the waypoint (``mix = 1``: the paper's ``w_t - p_t``). Continuing the current motion is something
    the body can do next (a torque-driven arm cannot stop or start within a step, a unicycle cannot move
    sideways), so a query near it stays inside M_phi's training data, where its labels hold, and the
    labels change smoothly with the state, which the clone can fit."""
    if mix == 1.0:
        return toward
    return (1.0 - mix) * last + mix * toward


def query_inputs(tr: Transitions, frame: str = "world", scale: str = "raw", mix: float = 1.0,
                 step_change: bool = False) -> np.ndarray:
    """What a label source keeps per row for M_phi's queries: :func:`query_displacement` ``(T, d')``, and with
    ``step_change`` the last step ``p_t - p_{t-1}`` ``(T, d)`` after it (the change block is formed once the
    query is clipped: ``InverseDynamics.ask``)."""
    q = query_displacement(tr, frame, scale, mix)
    if not step_change:
        return q
    return np.concatenate([q, last_step(tr).astype(np.float32)], axis=1)  # (T, d' + d)


def query_displacement(tr: Transitions, frame: str = "world", scale: str = "raw", mix: float = 1.0) -> np.ndarray:
    """The displacement ``(T, d)`` M_phi is asked to produce from ``s_t``.

    - ``raw`` (paper): ``waypoint_t - position_t``, with ``mix < 1`` mixed with the last step
      (:func:`mixed_query`);
    - ``own_step``: its direction, at the length of the step the agent actually took from ``s_t``
      (``|position_{t+1} - position_t|``; an episode's last step takes the one before it): "head for the
      waypoint at the pace you go", a query inside the one-step training data by construction, whose label
      corrects the heading and keeps the member's own pace.
    """
    toward = tr.waypoint - tr.position
    if mix != 1.0 and len(tr):
        toward = mixed_query(toward.astype(np.float64), last_step(tr), mix)
    q = to_frame(tr, toward.astype(np.float32), frame)  # (T, d)
    if scale == "raw" or len(tr) == 0:
        return q
    if scale != "own_step":
        raise ValueError(f"query scale must be one of {QUERY_SCALES}, got {scale!r}")
    end, idx = episode_end(tr), np.arange(len(tr))
    nxt = np.minimum(idx + 1, end)  # (T,) the successor in the episode (itself on the last step)
    first = np.append(True, end[:-1] == idx[:-1])  # (T,) a row that follows an episode's last step
    step = np.linalg.norm(tr.position[nxt] - tr.position, axis=1)  # (T,) |p_{t+1} - p_t|
    last = (nxt == idx) & ~first  # an episode's last step: the step into it
    step[last] = step[idx[last] - 1]
    n = np.linalg.norm(q, axis=1)  # (T,)
    return (q * (step / np.maximum(n, 1e-12))[:, None]).astype(np.float32)  # (T, d)
