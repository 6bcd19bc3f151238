"""Returns of the waypoint controller, zero action and random action on 100 episodes (seeds 1000-1099)."""
import sys, json
import numpy as np, gymnasium as gym
import hover

def run(kind, seeds):
    env = gym.make("Hover-v0")
    rets, reached, lens = [], 0, []
    rng = np.random.default_rng(0)
    for sd in seeds:
        obs, info = env.reset(seed=sd)
        tot, done, t = 0.0, False, 0
        while not done:
            if kind == "controller":
                a = env.unwrapped.waypoint_controller(obs, info)
            elif kind == "zero":
                a = np.zeros(2, np.float32)
            else:
                a = rng.uniform(-1, 1, 2).astype(np.float32)
            obs, r, term, trunc, info = env.step(a)
            tot += r; t += 1; done = term or trunc
        reached += float(np.linalg.norm(env.unwrapped.goal - env.unwrapped.pos)) < 0.3
        rets.append(tot); lens.append(t)
    rets = np.array(rets)
    return dict(kind=kind, mean=round(rets.mean(), 4), std=round(rets.std(), 4), min=round(rets.min(), 4),
                max=round(rets.max(), 4), reached_goal=int(reached), mean_len=float(np.mean(lens)))

seeds = range(1000, 1100)
out = [run(k, seeds) for k in ("controller", "zero", "random")]
for o in out: print(json.dumps(o))
