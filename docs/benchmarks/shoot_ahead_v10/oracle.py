"""The shooting labels with the simulator as their model (an upper bound): each step, the held action (of
forward_shoot.candidate_actions) whose next h simulated steps pass nearest the aim, the aim being the waypoint
plus ext times the waypoint path's last step (w - the waypoint before it); mean return of 30 episodes.

    python docs/benchmarks/shoot_ahead_v10/oracle.py Kart-v0
"""
import sys, dataclasses, numpy as np, gymnasium as gym
import shaped_es
from shaped_es.envs.core import get_batch_core
from shaped_es.shaping.forward_shoot import candidate_actions
env_id = sys.argv[1]
core = get_batch_core(gym.make(env_id))
seeds = np.arange(1000, 1030)
def rep(state, K):
    return type(state)(**{f.name: np.repeat(getattr(state, f.name), K, axis=0) for f in dataclasses.fields(state)})
def run(h, ext):
    state, obs, info = core.reset(seeds); B = len(seeds)
    A = candidate_actions(2); K = len(A)  # the planar bodies' 2-D actions
    ret = np.zeros(B); alive = np.ones(B, bool)
    w_prev = np.asarray(info["position"], float).copy(); w_cur = np.asarray(info["waypoint"], float).copy()
    for t in range(core.max_steps):
        w = np.asarray(info["waypoint"], float)
        changed = np.any(w != w_cur, axis=1)
        w_prev[changed] = w_cur[changed]; w_cur = w.copy()
        aim = np.repeat(w + ext * (w - w_prev), K, 0)
        s = rep(state, K); a = np.tile(A, (B, 1))
        best = np.full(B * K, np.inf)
        for i in range(h):
            s, *_ = core.step(s, a)
            best = np.minimum(best, np.linalg.norm(s.pos - aim, axis=1))
        pick = best.reshape(B, K).argmin(1)
        state, obs, r, term, trunc, info = core.step(state, A[pick])
        ret += np.where(alive, r, 0); alive &= ~(np.asarray(term) | np.asarray(trunc))
        if not alive.any(): break
    return ret.mean()
for h in (4, 8):
    print(env_id, f"h={h} " + " ".join(f"ext{e}: {run(h, e):.2f}" for e in (0.0, 0.5, 1.0, 2.0)), flush=True)
