import itertools, numpy as np, gymnasium as gym, plate
def run(kp,kd,ka,n=30):
    env=gym.make("Plate-v0"); u=env.unwrapped
    u.KP,u.KD,u.KA=kp,kd,ka
    R=[];falls=0
    for s in range(n):
        o,i=env.reset(seed=s); tot=0
        while True:
            o,r,te,tr,i=env.step(u.waypoint_controller(o,i)); tot+=r
            if te: falls+=1
            if te or tr: break
        R.append(tot)
    return np.mean(R),np.std(R),falls
best=[]
for kp,kd,ka in itertools.product([2,4,6,10,15],[2,3,4.5,6,8],[5,10,20,40]):
    m,s,f=run(kp,kd,ka,20); best.append((m,kp,kd,ka,f))
best.sort(reverse=True)
for b in best[:8]: print(b)
m=best[0]; print("seeds 0-49:", run(*m[1:4],50))
