"""Scores of zero action, random action and the scripted controller on Arm7Reach-v0 (seeds 0-49)."""
import sys
import gymnasium as gym, numpy as np
import arm7_reach  # noqa: F401

def run(policy, seed, **kw):
    env = gym.make("Arm7Reach-v0")
    obs, info = env.reset(seed=seed)
    R = 0.0; dists = []; done = False
    while not done:
        a = policy(env, obs, info, **kw)
        obs, r, term, trunc, info = env.step(a)
        R += r; dists.append(info["dist"]); done = term or trunc
    return R, np.mean(dists), info["goal_dist"], np.linalg.norm(info["goal"] - env.unwrapped.start)

zero = lambda env, o, i: np.zeros(7)
rng = np.random.default_rng(0)
rand = lambda env, o, i: rng.uniform(-2, 2, 7)
def ctrl(env, o, i, **kw):
    return env.unwrapped.waypoint_controller(o, i, **kw)

seeds = range(50)
for name, pol, kw in [("zero", zero, {}), ("random", rand, {}), ("controller", ctrl, {})] + [
        (f"ctrl kp={kp} kv={kv} kn={kn}", ctrl, dict(kp=kp, kv=kv, kn=kn))
        for kp, kv, kn in ([] if "-v" in sys.argv else [])]:
    res = np.array([run(pol, s, **kw) for s in seeds])
    print(f"{name:28s} return mean {res[:,0].mean():7.2f} median {np.median(res[:,0]):7.2f} min {res[:,0].min():7.2f} max {res[:,0].max():7.2f} | mean dist {res[:,1].mean():.3f} | final goal dist {res[:,2].mean():.3f} | start-goal {res[:,3].mean():.3f}")
