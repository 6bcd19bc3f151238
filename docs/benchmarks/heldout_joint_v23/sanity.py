"""Sanity checks of joint.py: controller / zero / random returns, wrap crossings, waypoint consumption."""
import sys
import gymnasium as gym
import numpy as np
import joint

def run(policy, seeds, kp=None):
    rets, cross, jumps, reached = [], 0, 0, 0
    for s in seeds:
        env = gym.make("JointArm-v0")
        obs, info = env.reset(seed=s)
        u = env.unwrapped
        e0 = joint.wrap(u.goal - u.q0)
        cross += any(abs(u.q0[j] + e0[j]) > np.pi for j in range(2))
        R, p = 0.0, info["position"]
        rng = np.random.default_rng(s)
        for t in range(100):
            a = policy(u, obs, info, rng)
            obs, r, term, trunc, info = env.step(a)
            jumps += np.any(np.abs(info["position"] - p) > np.pi); p = info["position"]
            R += r
            if term or trunc: break
        reached += np.linalg.norm(joint.wrap(u.goal - u.q)) < 0.1
        rets.append(R)
    return np.mean(rets), np.std(rets), cross, jumps, reached

if __name__ == "__main__":
    ctrl = lambda u, o, i, rng: u.waypoint_controller(o, i)
    zero = lambda u, o, i, rng: np.zeros(2, np.float32)
    rand = lambda u, o, i, rng: rng.uniform(-1, 1, 2)
    def pd(kp, kd):
        return lambda u, o, i, rng: np.clip(kp * joint.wrap(u.goal - u.q) - kd * u.qd, -1, 1)
    seeds = range(200)
    for name, pol in [("controller", ctrl), ("zero", zero), ("random", rand), ("PD-to-goal 8/1", pd(8, 1)),
                      ("PD-to-goal 3/1", pd(3, 1)), ("PD-to-goal 20/2", pd(20, 2))]:
        m, s, c, j, r = run(pol, seeds)
        print(f"{name:16s} return {m:8.2f} +- {s:6.2f}  episodes crossing +-pi (short way) {c}/200  position jumps {j}  goal reached at end {r}/200")
