import time, numpy as np, gymnasium as gym, dig
env = gym.make("Excavator-v0")
def run(pol, seeds=range(20)):
    R=[];E=[];M=[]
    for s in seeds:
        o,i=env.reset(seed=s); tot=0; d=[]; done=False
        while not done:
            a=pol(o,i); o,r,te,tr,i=env.step(a); tot+=r; done=te or tr
            d.append(np.linalg.norm(i["position"]-env.unwrapped.path[env.unwrapped.t]))
        R.append(tot); E.append(np.mean(d)); M.append(np.max(d))
    return np.mean(R), np.std(R), np.mean(E), np.mean(M)
u=env.unwrapped
t=time.time(); print("ctrl", run(lambda o,i: u.waypoint_controller(o,i))); print(time.time()-t)
print("zero", run(lambda o,i: np.zeros(3)))
rng=np.random.default_rng(0)
t=time.time(); print("rand", run(lambda o,i: rng.uniform(-1,1,3))); print("s/4000 steps", time.time()-t)
