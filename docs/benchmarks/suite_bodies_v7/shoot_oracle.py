"""Upper bound: random/grid shooting with the simulator as its model: the held action whose h-step end is
nearest the waypoint (or whose path passes nearest)."""
import sys, numpy as np, gymnasium as gym
import shaped_es
from shaped_es.envs.core import get_batch_core
env_id = sys.argv[1]
core = get_batch_core(gym.make(env_id))
seeds = np.arange(1000, 1020)
g = np.linspace(-1, 1, 5)
A = np.array([[x, y] for x in g for y in g], np.float32)  # (K, 2)
def rep(state, K):
    import dataclasses
    return type(state)(**{f.name: np.repeat(getattr(state, f.name), K, axis=0) for f in dataclasses.fields(state)})
def run(h, mode):
    state, obs, info = core.reset(seeds); B = len(seeds); K = len(A)
    ret = np.zeros(B); alive = np.ones(B, bool)
    for t in range(core.max_steps):
        w = np.repeat(info["waypoint"], K, 0)
        s = rep(state, K); a = np.tile(A, (B, 1))
        best = np.full(B * K, np.inf)
        for i in range(h):
            s, *_ = core.step(s, a)
            dist = np.linalg.norm(s.pos - w, axis=1)
            best = np.minimum(best, dist) if mode == "min" else dist
        pick = best.reshape(B, K).argmin(1)
        state, obs, r, term, trunc, info = core.step(state, A[pick])
        ret += np.where(alive, r, 0); alive &= ~(term | trunc)
        if not alive.any(): break
    return ret.mean()
for h in (1, 4, 8, 16):
    for mode in ("end", "min"):
        print(env_id, f"h={h} {mode}: {run(h, mode):.2f}", flush=True)
