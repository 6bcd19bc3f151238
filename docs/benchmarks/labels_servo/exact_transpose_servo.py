exec(open(__import__("pathlib").Path(__file__).with_name("exact_inverse_servo.py")).read().split('print("zero"')[0])
def runT(h, K, k, damp):
    state, obs, info = core.reset(seeds)
    B = len(seeds); ret = np.zeros(B); prev = info["position"].copy()
    for t in range(50):
        p, w = info["position"], info["waypoint"]
        v = p - prev
        b = roll(state, np.zeros((B, 2), np.float32), h) - p
        A = np.stack([roll(state, np.tile(np.eye(2, dtype=np.float32)[j], (B, 1)), h) - p - b for j in range(2)], -1)
        A = A / np.linalg.norm(A, axis=(1, 2), keepdims=True)  # direction only
        err = K * (w - p) - damp * v  # desired velocity change (per step units)
        a = np.clip(k * (np.swapaxes(A, 1, 2) @ err[..., None])[..., 0], -1, 1).astype(np.float32)
        prev = p.copy()
        state, obs, r, te, tr, info = core.step(state, a)
        ret += r
    return ret.mean()
for h in (1, 2):
  for K in (1.0,):
    for damp in (0.0, 1.0, 3.0, 10.0):
        print(h, damp, [round(runT(h, K, k, damp), 2) for k in (2, 5, 10, 20, 40)], flush=True)
