import sys, numpy as np, gymnasium as gym, quad2d
def run(policy, n=100):
    env = gym.make("Quad2D-v0"); R=[]; crash=0; fd=[]; L=[]
    for s in range(n):
        obs, info = env.reset(seed=1000+s); tot=0; done=False; t=0
        rng = np.random.default_rng(s)
        while not done:
            a = policy(env, obs, info, rng)
            obs, r, term, trunc, info = env.step(a); tot+=r; done=term or trunc; t+=1
        R.append(tot); crash+=term; fd.append(env.unwrapped.dist); L.append(t)
    R=np.array(R); return R.mean(), R.std(), np.percentile(R,[10,50,90]), crash, np.mean(fd), np.mean(L)
print("zero", run(lambda e,o,i,r: np.zeros(2)))
print("random", run(lambda e,o,i,r: r.uniform(-1,1,2)))
print("ctrl", run(lambda e,o,i,r: e.unwrapped.waypoint_controller(o,i)))
