# controller and zero action on evaluate's 15 episode seeds
import json, numpy as np, gymnasium as gym, plate
seeds = json.loads(open("eval_s0.json").read().strip().splitlines()[-1])["episode_seeds"]
env = gym.make("Plate-v0"); u = env.unwrapped
for name, pol in [("controller", lambda o, i: u.waypoint_controller(o, i)), ("zero", lambda o, i: np.zeros(2, np.float32))]:
    R = []
    for s in seeds:
        o, i = env.reset(seed=s); tot = 0.0
        while True:
            o, r, te, tr, i = env.step(pol(o, i)); tot += r
            if te or tr: break
        R.append(tot)
    print(name, round(np.mean(R), 2), round(np.std(R), 2))
