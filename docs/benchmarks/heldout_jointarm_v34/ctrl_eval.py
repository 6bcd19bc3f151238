"""Evaluate scripted PD controllers on JointArm-v0 (seeds 0..N-1)."""
import sys
import numpy as np
import gymnasium as gym
import jointarm

def run(policy, seeds=range(50)):
    rets, holds = [], []
    for s in seeds:
        env = gym.make("JointArm-v0")
        obs, info = env.reset(seed=s)
        R = 0.0; h = 0
        for t in range(150):
            a = policy(env.unwrapped, obs, info)
            obs, r, term, trunc, info = env.step(a)
            R += r
            if r >= 0.5 - 1e-9 and np.linalg.norm(env.unwrapped.goal - env.unwrapped.q) < 0.08: h += 1
            if term or trunc: break
        rets.append(R); holds.append(h)
    rets = np.array(rets)
    return rets.mean(), rets.std(ddof=1) / np.sqrt(len(rets)), np.mean(holds)

def pd_goal(kp, kd):
    def p(env, obs, info):
        return env.waypoint_controller(obs, info, kp=kp, kd=kd)
    return p

def pd_wp(kp, kd):
    def p(env, obs, info):
        q = obs[0:3].astype(float); qd = obs[3:6].astype(float)
        e = info["waypoint"] - q
        tau = kp * e - kd * qd
        tau[0] += 0.5 * np.sin(q[0]) / 4.0
        return np.clip(tau, -1, 1)
    return p

print("zero", run(lambda e, o, i: np.zeros(3)))
for kp in [1, 2, 3, 5, 8]:
    for kd in [0.5, 1.0, 1.5, 2.5]:
        print("goal kp=%g kd=%g" % (kp, kd), run(pd_goal(kp, kd)))
for kp in [3, 5, 8, 12]:
    for kd in [0.5, 1.0, 1.5, 2.5]:
        print("wp kp=%g kd=%g" % (kp, kd), run(pd_wp(kp, kd)))
