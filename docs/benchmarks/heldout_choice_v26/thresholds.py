"""Each body's threshold: 80% of a scripted controller's mean return over reset seeds 0-99 (zero action: 0.00)."""
import gymnasium as gym
import numpy as np

import md_bodies  # noqa: F401 - registers GridMD-v0, Thrusters-v0


def grid(env):  # an axis stays once within half a step of the goal, else steps toward it
    d = env.unwrapped.goal - env.unwrapped.pos
    return np.where(np.abs(d) < 0.025, 0, np.where(d > 0, 1, 2))


def thrusters(env):  # a PD law on the goal offset, each thruster on where its axis' force is
    u = env.unwrapped
    f = 2.0 * (u.goal - u.pos) - 60.0 * u.vel
    return np.array([f[0] > 0.05, f[0] < -0.05, f[1] > 0.05, f[1] < -0.05]).astype(np.int8)


for env_id, ctl in (("GridMD-v0", grid), ("Thrusters-v0", thrusters)):
    env, returns = gym.make(env_id), []
    for seed in range(100):
        env.reset(seed=seed)
        total, done = 0.0, False
        while not done:
            _, r, term, trunc, _ = env.step(ctl(env))
            total, done = total + r, term or trunc
        returns.append(total)
    print(f"{env_id}: controller {np.mean(returns):.2f}, threshold (80%) {0.8 * np.mean(returns):.2f}")
