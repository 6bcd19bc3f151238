"""Scripted controller, zero action and random actions on both bodies (seeds 0..N-1)."""
import sys, time
import numpy as np, gymnasium as gym
import noisy_bodies  # noqa: F401

def run(env_id, policy, n=200, **kw):
    env = gym.make(env_id, **kw)
    R = []; L = []; reached = 0
    for seed in range(n):
        obs, info = env.reset(seed=seed)
        tot, done, t = 0.0, False, 0
        while not done:
            if policy == "ctrl":
                a = env.unwrapped.waypoint_controller(obs, info)
            elif policy == "zero":
                a = np.zeros(2, np.float32)
            else:
                a = env.action_space.sample()
            obs, r, term, trunc, info = env.step(a)
            tot += r; t += 1; done = term or trunc
        reached += term; R.append(tot); L.append(t)
    R = np.array(R)
    return R.mean(), R.std(ddof=1) / np.sqrt(n), reached / n, np.mean(L)

for env_id in ["NoisyPoint-v0", "SlipDrive-v0"]:
    for pol in ["ctrl", "zero", "random"]:
        t = time.time()
        m, se, reach, L = run(env_id, pol)
        print(f"{env_id:14s} {pol:6s} mean {m:7.3f} +- {se:.3f} (se)  reached {reach:.2f}  mean len {L:.1f}  ({time.time()-t:.1f}s)")
if len(sys.argv) > 1:
    m, se, reach, L = run("NoisyPoint-v0", "ctrl", noise_scale=0.0)
    print("NoisyPoint noise off ctrl", m, reach, L)
    m, se, reach, L = run("SlipDrive-v0", "ctrl", slip_lo=1.0, heading_std=0.0)
    print("SlipDrive noise off ctrl", m, reach, L)
