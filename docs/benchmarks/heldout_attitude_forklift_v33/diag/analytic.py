"""Drive Attitude-v0 with the perfect one-step inverse's labels (the query clipped to c x the mean babbling step)."""
import sys
import numpy as np, gymnasium as gym
sys.path.insert(0, "/work/exp/s36/attitude")
import attitude as A

env = gym.make("Attitude-v0")
# mean babbling step
rng = np.random.default_rng(0); steps = []
for ep in range(20):
    o, info = env.reset(seed=1000 + ep); p = info["position"].copy()
    for t in range(120):
        o, r, te, tr, info = env.step(rng.uniform(-1, 1, 3)); q = info["position"]
        d = q - p; d[2] = (d[2] + np.pi) % (2 * np.pi) - np.pi; steps.append(np.linalg.norm(d)); p = q.copy()
        if te or tr: break
mean_step = float(np.mean(steps)); print("mean babbling step", round(mean_step, 4))

def drive(label, n=10):
    rets = []
    for ep in range(n):
        o, info = env.reset(seed=ep); R = 0
        for t in range(120):
            o, r, te, tr, info = env.step(label(o, info)); R += r
            if te or tr: break
        rets.append(R)
    return np.mean(rets), np.mean([r > 15 for r in rets])

def inverse(c, target="waypoint"):
    def label(o, info):
        w = info[target] - info["position"]; w[2] = (w[2] + np.pi) % (2 * np.pi) - np.pi
        n = np.linalg.norm(w)
        if c is not None and n > c * mean_step: w = w * (c * mean_step / n)
        rate = o[4:7].astype(np.float64)
        a = (w / A.DT - rate * (1 - A.DT * A.DAMPING)) / (A.DT * A.GAIN)
        return np.clip(a, -1, 1).astype(np.float32)
    return label

print("controller", drive(lambda o, i: env.unwrapped.waypoint_controller(o, i)))
print("zero", drive(lambda o, i: np.zeros(3, np.float32)))
for c in (None, 0.5, 1, 2, 4, 8):
    print("inverse clip", c, drive(inverse(c)), "goal-aimed", drive(inverse(c, "goal")))
