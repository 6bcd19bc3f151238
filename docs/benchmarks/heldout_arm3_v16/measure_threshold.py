"""Returns of reference policies on Arm3-v0 over 100 episodes (seeds 0-99), and the threshold.

- zero: zero action (the arm stays where it starts)
- random: uniform random joint velocities
- pinv_target: Jacobian pseudo-inverse straight toward the target (ignores the schedule)
- controller: the env's waypoint_controller, Jacobian pseudo-inverse toward the scheduled waypoint
  (info["waypoint"]); a straight-line tracker of the start-to-target line

Threshold = zero + 0.9 * (best hand controller - zero), rounded down to 0.1.
Run from this folder: python measure_threshold.py
"""

import math

import gymnasium as gym
import numpy as np

import arm3

EPISODES = 100


def run(policy_name, seed):
    env = gym.make("Arm3-v0")
    obs, info = env.reset(seed=seed)
    u = env.unwrapped
    rng = np.random.default_rng(10_000 + seed)
    total, done = 0.0, False
    while not done:
        if policy_name == "zero":
            a = np.zeros(3)
        elif policy_name == "random":
            a = rng.uniform(-1, 1, 3)
        elif policy_name == "pinv_target":
            err = u.target - arm3.fk(u.q)
            qdot = np.linalg.pinv(arm3.jacobian(u.q)) @ (err / arm3.DT)
            a = qdot / arm3.QDOT_SCALE
            m = np.max(np.abs(a))
            a = a / m if m > 1 else a
        else:
            a = u.waypoint_controller(obs, info)
        obs, r, term, trunc, info = env.step(a)
        total += r
        done = term or trunc
    final_err = float(np.linalg.norm(arm3.fk(u.q) - u.target))
    env.close()
    return total, final_err


def main():
    res = {}
    for name in ["zero", "random", "pinv_target", "controller"]:
        out = np.array([run(name, s) for s in range(EPISODES)])
        rets, errs = out[:, 0], out[:, 1]
        res[name] = rets.mean()
        print(
            f"{name:12s} return mean {rets.mean():8.3f} (sd {rets.std():.3f}, min {rets.min():.2f}, "
            f"max {rets.max():.2f}); final distance to target median {np.median(errs):.3f}, "
            f"within 0.05 m: {np.mean(errs < 0.05) * 100:.0f}%"
        )
    best = max(res["pinv_target"], res["controller"])
    thr = res["zero"] + 0.9 * (best - res["zero"])
    print(f"threshold = zero + 0.9 * (best controller - zero) = {res['zero']:.3f} + 0.9 * ({best:.3f} - "
          f"{res['zero']:.3f}) = {thr:.3f} -> {math.floor(thr * 10) / 10:.1f}")


if __name__ == "__main__":
    main()
