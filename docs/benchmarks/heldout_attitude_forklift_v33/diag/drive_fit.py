"""Drive Attitude-v0 with a fitted M_phi's labels (world frame, the query clipped to c x the mean training step):
is a well-fitted one-step model's label good here (the perfect inverse's: analytic.txt)?"""
import sys
import numpy as np, gymnasium as gym
sys.argv = [sys.argv[0], "attitude:Attitude-v0", "1"] + sys.argv[1:]
exec(open("fit.py").read().split("eid = sys.argv[1]")[0])  # collect() and imports
env = gym.make("Attitude-v0")
period = np.array([0, 0, 2 * np.pi])
data = [collect(env, 100 + g, 16, period=period) for g in range(2)]
for lr, steps in ((1e-3, 1000), (1e-3, 8000), (1e-2, 1000), (1e-2, 2000)):
    cfg = InverseDynamicsConfig(frame="world", targets="one_step", min_return=-1e9, seed=0, lr=lr)
    m = InverseDynamics(10, 3, 3, cfg); m.add(data); m.train(steps)
    x = m.newest(m.dataset_size)[0][:, 10:]; mean_step = float(np.linalg.norm(x, axis=1).mean())
    out = []
    for c in (None, 1, 2, 4):
        rets = []
        for ep in range(10):
            o, info = env.reset(seed=ep); R = 0
            for t in range(120):
                w = info["waypoint"] - info["position"]; w[2] = (w[2] + np.pi) % (2 * np.pi) - np.pi
                n = np.linalg.norm(w)
                if c is not None and n > c * mean_step: w = w * (c * mean_step / n)
                a = m.label(o[None].astype(np.float32), w[None].astype(np.float32))[0]
                o, r, te, tr, info = env.step(a); R += r
                if te or tr: break
            rets.append(R)
        out.append(f"clip {c}: {np.mean(rets):.1f}")
    print(f"lr {lr} steps {steps} (mean step {mean_step:.4f}): " + " | ".join(out), flush=True)
