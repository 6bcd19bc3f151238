"""Upper bound: the servo with the simulator as its h-step held-action forward model."""
import sys, numpy as np, gymnasium as gym
import shaped_es
from shaped_es.envs.core import get_batch_core
env_id = sys.argv[1]
core = get_batch_core(gym.make(env_id))
seeds = np.arange(1000, 1020)
FD = 0.5
def fh(state, a, h):
    s = state
    p0 = s.pos.copy()
    for _ in range(h):
        s, *_ = core.step(s, a)
    return s.pos - p0
def run(h, c, k):
    state, obs, info = core.reset(seeds); B = len(seeds)
    ret = np.zeros(B); alive = np.ones(B, bool)
    q = np.median(np.linalg.norm(info["waypoint"] - info["position"], axis=1))
    for t in range(core.max_steps):
        err = info["waypoint"] - info["position"]
        z = np.zeros((B, 2), np.float32)
        drift = fh(state, z, h)
        G = np.stack([(fh(state, z + FD * np.eye(2, dtype=np.float32)[j], h) - drift) / FD for j in range(2)], -1)  # (B, d, act)
        G /= np.maximum(np.linalg.norm(G, axis=(1, 2), keepdims=True), 1e-12)
        e = (err - c * drift) / q
        a = np.clip(k * np.einsum("nda,nd->na", G, e), -1, 1).astype(np.float32)
        state, obs, r, term, trunc, info = core.step(state, a)
        ret += np.where(alive, r, 0); alive &= ~(term | trunc)
        if not alive.any(): break
    return ret.mean()
for h in (1, 4, 8):
    for c in (0.0, 1.0, 3.0):
        for k in (1.0, 3.0):
            print(env_id, f"h={h} c={c} k={k}: {run(h, c, k):.2f}", flush=True)
