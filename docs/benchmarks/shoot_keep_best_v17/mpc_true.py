"""Feasibility: model-predictive labels over action SEQUENCES with the true simulator as the model, on the
drone. Each state is planned from scratch (CEM, no warm start: a label per recorded state, as the framework
would). Cost: position only (the framework knows info['position'] and info['waypoint'], nothing else)."""
import sys, time
import numpy as np
sys.path.insert(0, str(__import__('pathlib').Path(__file__).resolve().parent.parent / 'heldout_drone_v16'))
import drone as D  # noqa: E402  (../heldout_drone_v16/drone.py)

def batch_step(S, A):
    # S (K, 6), A (K, 2)
    a = np.clip(A, -1, 1)
    t1 = (a[:, 0] + 1) * 0.5 * D.T_MAX; t2 = (a[:, 1] + 1) * 0.5 * D.T_MAX
    x, z, th, vx, vz, om = S.T
    f = t1 + t2
    vx = vx + (f * np.sin(th) / D.MASS - D.DRAG * vx) * D.DT
    vz = vz + (f * np.cos(th) / D.MASS - D.G - D.DRAG * vz) * D.DT
    om = om + ((t1 - t2) * D.ARM / D.INERTIA - D.ANG_DRAG * om) * D.DT
    x = x + vx * D.DT; z = z + vz * D.DT; th = th + om * D.DT
    return np.stack([x, z, th, vx, vz, om], 1)

def plan(s, w, H, cost, K=64, iters=3, elite=8, rng=None):
    mu = np.zeros((H, 2)); sd = np.full((H, 2), 0.5)
    for _ in range(iters):
        A = np.clip(mu + sd * rng.standard_normal((K, H, 2)), -1, 1)
        S = np.repeat(s[None], K, 0)
        d = np.zeros((K, H))
        for j in range(H):
            S = batch_step(S, A[:, j])
            d[:, j] = np.linalg.norm(S[:, :2] - w, axis=1)
        c = d.min(1) if cost == "min" else (d.mean(1) if cost == "mean" else d[:, -1])
        e = A[np.argsort(c)[:elite]]
        mu, sd = e.mean(0), e.std(0) + 0.05
    return mu[0]

def episode(seed, H, cost):
    env = D.Drone(); obs, info = env.reset(seed=seed); rng = np.random.default_rng(seed)
    R = 0.0
    for t in range(D.MAX_STEPS):
        a = plan(env.s.copy(), info["waypoint"], H, cost, rng=rng)
        obs, r, term, trunc, info = env.step(a); R += r
        if term: break
    return R, info.get("crashed", False)

if __name__ == "__main__":
    for H in [int(h) for h in sys.argv[1].split(",")]:
        for cost in sys.argv[2].split(","):
            t0 = time.time()
            res = [episode(s, H, cost) for s in range(8)]
            R = np.array([r for r, _ in res]); cr = sum(c for _, c in res)
            print(f"H={H} cost={cost}: mean return {R.mean():.2f} (min {R.min():.2f}, max {R.max():.2f}), crashes {cr}/8, {time.time()-t0:.0f}s", flush=True)
