import sys
import numpy as np, gymnasium as gym
import shaped_es.envs  # noqa
from shaped_es.envs.core import get_batch_core
core = get_batch_core(gym.make("ReacherWay-v0"))
seeds = np.arange(20)

def roll(state, a, h):
    s = state
    for _ in range(h):
        s, obs, r, te, tr, info = core.step(s, a)
    return info["position"]

def run(h, K, beta, lam=1e-6):
    state, obs, info = core.reset(seeds)
    B = len(seeds); ret = np.zeros(B); prev = info["position"].copy()
    for t in range(50):
        p, w = info["position"], info["waypoint"]
        v = p - prev
        q = h * (v + beta * (K * (w - p) - v))  # desired h-step displacement
        b = roll(state, np.zeros((B, 2), np.float32), h) - p
        A = np.stack([roll(state, np.tile(np.eye(2, dtype=np.float32)[j], (B, 1)), h) - p - b for j in range(2)], -1)
        M = np.swapaxes(A, 1, 2) @ A + lam * np.eye(2)
        a = np.clip(np.linalg.solve(M, (np.swapaxes(A, 1, 2) @ (q - b)[..., None]))[..., 0], -1, 1).astype(np.float32)
        prev = p.copy()
        state, obs, r, te, tr, info = core.step(state, a)
        ret += r
    return ret.mean()
print("zero", end=" "); 
state, obs, info = core.reset(seeds); ret=0
for t in range(50):
    state, obs, r, te, tr, info = core.step(state, np.zeros((20,2),np.float32)); ret = ret + r
print(ret.mean())
for h in (1, 2, 4):
    for K in (0.1, 0.2, 0.4):
        print(h, K, [round(run(h, K, beta), 2) for beta in (0.05, 0.1, 0.2, 0.5, 1.0)], flush=True)
