"""Which shooting labels drive a new user's crane when the model is the simulator itself (no learning).

Each step the label is the first action of the plan whose predicted payload path scores best against the aim; the
episode is driven by these labels alone (model-predictive control with the true dynamics), 10 episodes, seeds
1000-1009. It separates what the labels ask for from how well a learned model predicts:

- plans: ``held`` (one of a 5 x 5 grid of actions held the whole horizon: the shooting labels' candidates),
  ``two`` (two held actions, half the horizon each: 625 plans) and ``cem`` (the cross-entropy method over four
  held segments, 64 plans x 4 rounds);
- aim: ``past`` (the waypoint plus one step of the waypoint path past it: shoot_ahead 1, every waypoint) or
  ``hold`` (at the goal itself once the goal is the waypoint; elsewhere past);
- cost: the path's nearest pass (``min``) or its mean distance (``mean``) to the aim; ``min/mean``: min while
  passing waypoints, mean at the goal (what shoot_hold does).

python sim_labels.py  (needs ../heldout_crane_v34 on the path; ~3 min)
"""
import itertools
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "heldout_crane_v34"))
import crane as C  # noqa: E402

GRID = np.array(list(itertools.product(np.linspace(-1, 1, 5), repeat=2)))  # (25, 2)


def sim(state, acts):
    """``state`` (N, 5) trolley x, x', rope L, swing th, th'; ``acts`` (N, H, 2) -> payload positions (N, H, 2)."""
    x, xd, L, th, thd = (state[:, i].copy() for i in range(5))
    out = np.empty((len(x), acts.shape[1], 2))
    for j in range(acts.shape[1]):  # crane.py's step, vectorized
        a, b = np.clip(acts[:, j, 0], -1, 1), np.clip(acts[:, j, 1], -1, 1)
        xdd = 2.0 * a - 0.5 * xd
        thdd = -(C.G / L) * np.sin(th) - (xdd / L) * np.cos(th) - 0.2 * thd
        xd = xd + C.DT * xdd
        x = x + C.DT * xd
        thd = thd + C.DT * thdd
        th = th + C.DT * thd
        L = np.clip(L + C.DT * 0.5 * b, C.L_MIN, C.L_MAX)
        out[:, j, 0], out[:, j, 1] = x + L * np.sin(th), -L * np.cos(th)
    return out


def score(paths, aim, cost):
    d = np.linalg.norm(paths - aim, axis=-1)  # (K, H)
    return d.min(1) if cost == "min" else d.mean(1)


def held(st, aim, H, cost):
    return GRID[score(sim(np.repeat(st[None], len(GRID), 0), np.repeat(GRID[:, None], H, 1)), aim, cost).argmin()]


def two(st, aim, H, cost):
    a1, a2 = np.repeat(GRID, len(GRID), 0), np.tile(GRID, (len(GRID), 1))  # (625, 2) each
    acts = np.concatenate([np.repeat(a1[:, None], H // 2, 1), np.repeat(a2[:, None], H - H // 2, 1)], 1)
    return acts[score(sim(np.repeat(st[None], len(acts), 0), acts), aim, cost).argmin(), 0]


def cem(st, aim, H, cost, seg=4, n=64, rounds=4, elite=8):
    rng = np.random.default_rng(0)
    mu, sd = np.zeros((seg, 2)), np.ones((seg, 2))
    for _ in range(rounds):
        z = np.clip(mu + sd * rng.standard_normal((n, seg, 2)), -1, 1)  # (n, seg, 2)
        c = score(sim(np.repeat(st[None], n, 0), np.repeat(z, H // seg, axis=1)), aim, cost)
        e = z[np.argsort(c)[:elite]]
        mu, sd = e.mean(0), e.std(0) + 0.05
    return mu[0]


def drive(plan, H, cost, aim_rule):
    c_pass, c_goal = cost.split("/") if "/" in cost else (cost, cost)
    rets = []
    for s in range(10):
        env = C.Crane()
        obs, info = env.reset(seed=1000 + s)
        R, prev, before = 0.0, info["waypoint"].copy(), info["position"].copy()
        for _ in range(150):
            w = info["waypoint"]
            if not np.allclose(w, prev):
                before, prev = prev, w.copy()
            goal = aim_rule == "hold" and env.k == len(env.waypoints) - 1
            aim = w if goal else w + (w - before)
            st = np.array([env.x, env.xd, env.L, env.th, env.thd])
            obs, r, _, _, info = env.step(plan(st, aim, H, c_goal if goal else c_pass))
            R += r
        rets.append(R)
    return np.mean(rets), np.std(rets) / np.sqrt(len(rets))


if __name__ == "__main__":
    rets = []
    for s in range(10):
        env = C.Crane()
        obs, info = env.reset(seed=1000 + s)
        R = 0.0
        for _ in range(150):
            obs, r, _, _, info = env.step(env.waypoint_controller(obs, info))
            R += r
        rets.append(R)
    print(f"controller {np.mean(rets):.1f} +- {np.std(rets) / np.sqrt(10):.1f}")
    rows = [(p, H, c, a) for a in ("past", "hold") for p in ("held", "two", "cem") for H in (8, 16, 32)
            for c in ("min", "mean")] + [("held", H, "min/mean", "hold") for H in (8, 16, 32)]
    for p, H, c, a in rows:
        m, se = drive({"held": held, "two": two, "cem": cem}[p], H, c, a)
        print(f"aim {a:4s} plan {p:4s} horizon {H:2d} cost {c:8s} {m:6.1f} +- {se:4.1f}", flush=True)
