"""Drive Attitude-v0 with M_phi's labels, plain and with the velocity-change input (change.py), fitted 1000 and
4000 Adam steps (lr 1e-3) on 32 random-policy episodes; the query clipped to c x the mean training step."""
import sys
import numpy as np, gymnasium as gym
sys.argv = [sys.argv[0], "attitude:Attitude-v0", "1"]
src = open("change.py").read()
exec(src.split("eid = argv[0]")[0].replace("argv = sys.argv[1:]", "argv = ['attitude:Attitude-v0', '1']"))
env = gym.make("Attitude-v0")
period = np.array([0, 0, 2 * np.pi])
data = [collect(env, 100 + g, 16, period=period) for g in range(2)]
for change in (False, True):
    for total in (1000, 4000):
        cfg = InverseDynamicsConfig(frame="world", targets="one_step", min_return=-1e9, seed=0)
        m = InverseDynamics(10 + 3 * change, 3, 3, cfg)
        steps_ = []
        for tr in data:
            s, d, a = pairs(tr, change)
            x = np.c_[s, d].astype(np.float32); m.norm.update(x); m._append(x, a.astype(np.float32))
            steps_.append(np.linalg.norm(pairs(tr, False)[1], axis=1))
        m.train(total)
        mean_step = float(np.concatenate(steps_).mean())
        out = []
        for c in (None, 1, 2, 4):
            rets = []
            for ep in range(10):
                o, info = env.reset(seed=ep); R = 0; prevp = None
                for t in range(120):
                    p = info["position"].astype(np.float64)
                    if prevp is not None:
                        dd = p - prevp; dd[2] = (dd[2] + np.pi) % (2 * np.pi) - np.pi
                    else:
                        dd = np.zeros(3)
                    w = info["waypoint"] - p; w[2] = (w[2] + np.pi) % (2 * np.pi) - np.pi
                    n = np.linalg.norm(w)
                    if c is not None and n > c * mean_step: w = w * (c * mean_step / n)
                    s = np.r_[o, dd] if change else o
                    q = w - dd if change else w
                    a = m.label(s[None].astype(np.float32), q[None].astype(np.float32))[0]
                    prevp = p
                    o, r, te, tr_, info = env.step(a); R += r
                    if te or tr_: break
                rets.append(R)
            out.append(f"clip {c}: {np.mean(rets):.1f}")
        print(f"change={change} steps {total} (mean step {mean_step:.4f}): " + " | ".join(out), flush=True)
