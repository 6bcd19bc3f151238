import sys; sys.path.insert(0, "/work/main/src")
import numpy as np, gymnasium as gym
import shaped_es.envs  # noqa
from shaped_es.envs.core import get_batch_core
core = get_batch_core(gym.make("ReacherWay-v0"))
seeds = np.arange(20)

def roll(state, a, h):
    s, ps = state, []
    for _ in range(h):
        s, obs, r, te, tr, info = core.step(s, a); ps.append(info["position"])
    return ps[-1], ps[-1] - (ps[-2] if h > 1 else None)

def run(h, mu, gain=1.0, lam=1e-5):
    state, obs, info = core.reset(seeds)
    B = len(seeds); ret = np.zeros(B)
    for t in range(50):
        p, w = info["position"], info["waypoint"]
        q = gain * (w - p)
        def feat(a):
            pe, ve = roll(state, a, h)
            return np.concatenate([pe - p, np.sqrt(mu) * ve], 1)  # (B, 4)
        b = feat(np.zeros((B, 2), np.float32))
        A = np.stack([feat(np.tile(np.eye(2, dtype=np.float32)[j], (B, 1))) - b for j in range(2)], -1)  # (B,4,2)
        tgt = np.concatenate([q, np.zeros_like(q)], 1) - b
        M = np.swapaxes(A, 1, 2) @ A + lam * np.eye(2)
        a = np.clip(np.linalg.solve(M, (np.swapaxes(A, 1, 2) @ tgt[..., None]))[..., 0], -1, 1).astype(np.float32)
        state, obs, r, te, tr, info = core.step(state, a)
        ret += r
    return ret.mean()
for h in (2, 4, 6, 8):
    print(h, [round(run(h, mu), 2) for mu in (0.0, 1.0, 4.0, 16.0)])
