"""The same, with the shooting labels' candidate set: one action held for H steps (a 5 x 5 grid)."""
import sys
import numpy as np
sys.path.insert(0, str(__import__('pathlib').Path(__file__).resolve().parent.parent / 'heldout_drone_v16'))
import drone as D  # noqa: E402  (../heldout_drone_v16/drone.py)
from mpc_true import batch_step
from itertools import product
G = np.array(list(product(np.linspace(-1, 1, 5), repeat=2)))

def plan(s, w, H, cost):
    S = np.repeat(s[None], len(G), 0); d = np.zeros((len(G), H))
    for j in range(H):
        S = batch_step(S, G); d[:, j] = np.linalg.norm(S[:, :2] - w, axis=1)
    c = d.min(1) if cost == "min" else (d.mean(1) if cost == "mean" else d[:, -1])
    return G[np.argmin(c)]

def episode(seed, H, cost):
    env = D.Drone(); obs, info = env.reset(seed=seed); R = 0.0
    for t in range(D.MAX_STEPS):
        obs, r, term, trunc, info = env.step(plan(env.s.copy(), info["waypoint"], H, cost)); R += r
        if term: break
    return R, info.get("crashed", False)

for H in (2, 4, 8, 16):
    for cost in ("min", "mean", "last"):
        res = [episode(s, H, cost) for s in range(8)]
        R = np.array([r for r, _ in res])
        print(f"held H={H} {cost}: {R.mean():.2f} crashes {sum(c for _, c in res)}/8")
