import gymnasium as gym, numpy as np
import bicycle
env = gym.make("Bicycle-v0")
rets, lens, succ = [], [], 0
for seed in range(100):
    obs, info = env.reset(seed=1000 + seed)
    tot, done, n = 0.0, False, 0
    while not done:
        u = env.unwrapped
        a = bicycle.goal_controller(u.pos, u.th, u.goal)
        obs, r, term, trunc, info = env.step(a)
        tot += r; n += 1; done = term or trunc
    succ += term
    rets.append(tot); lens.append(n)
rets = np.array(rets)
print("mean %.3f std %.3f min %.3f success %d/100 mean len %.1f" % (rets.mean(), rets.std(), rets.min(), succ, np.mean(lens)))
print("90%% -> %.3f" % (0.9 * rets.mean()))
