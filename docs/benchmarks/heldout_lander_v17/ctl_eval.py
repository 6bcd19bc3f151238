import sys, numpy as np, gymnasium as gym, lander
env = gym.make("Lander-v0")
def run(policy, n=100):
    R=[]; succ=0; crash=0
    for s in range(1000, 1000+n):
        obs, info = env.reset(seed=s); tot=0
        for t in range(200):
            a = policy(obs, info)
            obs, r, term, trunc, info = env.step(a); tot+=r
            if term or trunc: break
        u=env.unwrapped
        succ += u.dist < 0.3; crash += (term and u.dist>=0.3)
        R.append(tot)
    R=np.array(R); return R.mean(), R.std(), np.median(R), succ, crash
print("controller", run(lambda o,i: env.unwrapped.waypoint_controller(o,i)))
print("zero", run(lambda o,i: np.zeros(2)))
rng=np.random.default_rng(0)
print("random", run(lambda o,i: rng.uniform(-1,1,2)))
