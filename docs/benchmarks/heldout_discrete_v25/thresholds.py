"""Each env's waypoint_controller over reset seeds 0-199: the mean return the thresholds are 80% of."""
import sys, numpy as np, gymnasium as gym
sys.path.insert(0, '.')  # run from the folder holding the two env files
import gridpoint, thrustcar
for eid in ("GridPoint-v0", "ThrustCar-v0"):
    env = gym.make(eid); R = []; fin = 0; out = 0
    for s in range(200):
        obs, info = env.reset(seed=s); ret = 0
        while True:
            obs, r, te, tr, info = env.step(env.unwrapped.waypoint_controller(obs, info)); ret += r
            if te or tr: break
        R.append(ret); fin += te and r > 0; out += r < -4
    R = np.array(R)
    print(eid, "controller mean %.3f se %.3f finished %d out %d; threshold %s" % (R.mean(), R.std(ddof=1)/np.sqrt(200), fin, out, env.spec.reward_threshold))
