import numpy as np, gymnasium as gym, diffbot
env = gym.make("DiffBot-v0")
def run(pol, seeds):
    out = []
    for s in seeds:
        obs, info = env.reset(seed=s); tot = 0; done = False
        while not done:
            obs, r, te, tr, info = env.step(pol(obs, info)); tot += r; done = te or tr
        out.append(tot)
    return np.array(out)
seeds = range(1000, 1200)
rng = np.random.default_rng(0)
res = {"zero": run(lambda o, i: np.zeros(2, np.float32), seeds),
       "random": run(lambda o, i: rng.uniform(-1, 1, 2).astype(np.float32), seeds),
       "controller": run(lambda o, i: env.unwrapped.waypoint_controller(o, i), seeds),
       "straight_fwd": run(lambda o, i: np.array([1, 0], np.float32), seeds)}
for k, v in res.items():
    print(f"{k:12s} mean {v.mean():6.3f} std {v.std():5.3f} min {v.min():6.3f} p10 {np.percentile(v,10):6.3f} frac>=8 {np.mean(v>=8):.2f} frac>=9 {np.mean(v>=9):.2f}")
