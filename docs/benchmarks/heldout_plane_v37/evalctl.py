import time, numpy as np, gymnasium as gym, plane
env = gym.make("Plane-v0")
def run(pol, n=50):
    R=[];P=[];N=[];why=[]
    t=time.time(); steps=0
    for s in range(n):
        o,i=env.reset(seed=s); tot=0; done=False
        while not done:
            a=pol(o,i)
            o,r,te,tr,i=env.step(a); tot+=r; done=te or tr; steps+=1
        R.append(tot); P.append(i["gates_passed"]); N.append(len(env.unwrapped.gates))
        why.append("end" if te and i["gate_index"]==N[-1]-1 and env.unwrapped.z>=0 and env.unwrapped.stall_count<15 else ("crash" if te else "trunc"))
    dt=time.time()-t
    print(f"mean {np.mean(R):.2f} std {np.std(R):.2f} gates {np.sum(P)}/{np.sum(N)} ", {k:why.count(k) for k in set(why)}, f"{steps/dt:.0f} steps/s")
run(lambda o,i: env.unwrapped.waypoint_controller(o,i))
run(lambda o,i: np.zeros(3,np.float32))
rng=np.random.default_rng(0)
run(lambda o,i: rng.uniform(-1,1,3).astype(np.float32))
