"""Measure the hand controller's return on Drone-v0 over 100 episodes; threshold = 0.9 x its mean.

The hand controller is Drone.waypoint_controller: PD on position -> desired acceleration -> desired
tilt (clipped to 0.5 rad) and total thrust -> rotor thrusts through a PD on pitch. It is run two ways:
aimed at the goal directly (the threshold's controller) and at info["waypoint"] (the waypoint
controller the oracle label source would use), for reference.

    python measure_threshold.py
"""
import gymnasium as gym
import numpy as np

import drone  # noqa: F401  (registers Drone-v0)

EPISODES = 100


def run(target: str, episodes: int = EPISODES, seed0: int = 10_000):
    env = gym.make("Drone-v0")
    rets, crashes, reached, lengths = [], 0, 0, []
    for ep in range(episodes):
        obs, info = env.reset(seed=seed0 + ep)
        u = env.unwrapped
        total, done, t = 0.0, False, 0
        while not done:
            tgt = u.goal if target == "goal" else None
            a = u.waypoint_controller(obs, info, target=tgt)
            obs, r, term, trunc, info = env.step(a)
            total += r
            t += 1
            done = term or trunc
        crashes += int(info.get("crashed", False))
        reached += int(u.dist < drone.GOAL_RADIUS)
        rets.append(total)
        lengths.append(t)
    rets = np.array(rets)
    return {"target": target, "mean": rets.mean(), "std": rets.std(), "min": rets.min(),
            "crashes": crashes, "reached_goal": reached, "mean_steps": float(np.mean(lengths))}


if __name__ == "__main__":
    for target in ("goal", "waypoint"):
        s = run(target)
        print(f"{target:8s}: mean {s['mean']:.3f} +- {s['std']:.3f} (min {s['min']:.3f}), "
              f"crashes {s['crashes']}/{EPISODES}, reached goal {s['reached_goal']}/{EPISODES}, "
              f"mean steps {s['mean_steps']:.1f}")
    g = run("goal")
    print(f"threshold = 0.9 x {g['mean']:.3f} = {0.9 * g['mean']:.3f}")
    # zero action (hover) and uniform random actions, for scale
    env = gym.make("Drone-v0")
    for name, pol in (("zero", lambda o: np.zeros(2, np.float32)),
                      ("random", lambda o: env.action_space.sample())):
        env.action_space.seed(0)
        rs = []
        for ep in range(EPISODES):
            o, _ = env.reset(seed=10_000 + ep)
            tot, done = 0.0, False
            while not done:
                o, r, te, tr, _ = env.step(pol(o))
                tot += r
                done = te or tr
            rs.append(tot)
        print(f"{name:8s}: mean {np.mean(rs):.3f}")
