import sys; sys.path.insert(0, "/work/main/src")
import numpy as np, gymnasium as gym
import shaped_es.envs  # noqa
from shaped_es.envs.core import get_batch_core
env = gym.make("ReacherWay-v0"); core = get_batch_core(env)
seeds = np.arange(20)

def hstep(state, a, h):
    s = state
    for _ in range(h):
        s, obs, r, te, tr, info = core.step(s, a)
    return info["position"]

def run(h, lam=1e-6, gain=1.0, ctrl=False):
    state, obs, info = core.reset(seeds)
    B = len(seeds); ret = np.zeros(B)
    for t in range(50):
        p, w = info["position"], info["waypoint"]
        if ctrl:
            a = core.waypoint_controller(state, obs, info)
        else:
            q = gain * (w - p)
            b = hstep(state, np.zeros((B, 2), np.float32), h) - p
            A = np.stack([hstep(state, np.tile(np.eye(2, dtype=np.float32)[j], (B, 1)), h) - p - b for j in range(2)], -1)  # (B,2,2)
            M = np.swapaxes(A, 1, 2) @ A + lam * np.eye(2)
            a = np.linalg.solve(M, (np.swapaxes(A, 1, 2) @ (q - b)[..., None]))[..., 0]
            a = np.clip(a, -1, 1).astype(np.float32)
        state, obs, r, te, tr, info = core.step(state, a)
        ret += r
    return ret.mean()
print("ctrl", run(1, ctrl=True))
for h in (1, 2, 3, 4, 6):
    for lam in (1e-8, 1e-5):
        print(h, lam, [round(run(h, lam, g), 2) for g in (1.0, 0.5, 0.25)])
