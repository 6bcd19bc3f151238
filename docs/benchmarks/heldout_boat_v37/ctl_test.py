import gymnasium as gym, numpy as np, time, boat
env = gym.make("Boat-v0")
rets=[]; holds=[]; t=time.time(); steps=0
for ep in range(30):
    obs, info = env.reset(seed=ep)
    R=0; h=0
    for _ in range(200):
        a = env.unwrapped.waypoint_controller(obs, info)
        obs, r, term, trunc, info = env.step(a); R+=r; steps+=1
        h += np.linalg.norm(info["goal"]-info["position"])<0.5
        if term or trunc: break
    rets.append(R); holds.append(h)
print("ctl", np.mean(rets), np.std(rets), np.min(rets), "hold steps", np.mean(holds), (time.time()-t)/steps*1e6, "us/step")
z=[]
for ep in range(30):
    obs, info = env.reset(seed=ep); R=0
    for _ in range(200):
        obs, r, term, trunc, info = env.step(np.zeros(2)); R+=r
        if term or trunc: break
    z.append(R)
print("zero", np.mean(z), np.std(z))
