"""Held-action shooting labels with the simulator as their model: does the label form itself drive a body?

    python oracle_shoot.py quad2d:Quad2D mean            # the quadrotor (its README's 4 / 8 / 16 / 32 steps)
    python oracle_shoot.py hover/hover:Hover mean,min    # the hovercraft

At each step every grid action (5 values per dimension) is held ``h`` steps on a copy of the env; the label is
the one whose path has the least mean distance (``mean``) or nearest pass (``min``) to the aim one waypoint
step past the waypoint, as ``shaping/forward_shoot.py`` scores a learned model's paths. 6 episodes, seeds 0-5.
A terminated path is padded with a far point (a crash is the worst path)."""
import copy
import importlib
import itertools
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
path, _, cls = sys.argv[1].partition(":")
sys.path.insert(0, os.path.join(HERE, os.path.dirname(path)))
Env = getattr(importlib.import_module(os.path.basename(path)), cls)
COSTS = sys.argv[2].split(",") if len(sys.argv) > 2 else ["mean"]
vals = np.linspace(-1, 1, 5)
A = np.array(list(itertools.product(vals, vals)))  # (25, 2)


def sim_path(env, a, h):
    e = copy.deepcopy(env); ps = []
    for _ in range(h):
        obs, r, term, trunc, info = e.step(a); ps.append(info['position'])
        if term: ps += [np.array([9., 9.])] * (h - len(ps)); break
    return np.array(ps)  # (h, 2)


def drive(h, cost, seeds, ahead=1.0):
    rets = []
    for s in seeds:
        env = Env(); obs, info = env.reset(seed=int(s)); ret = 0; wb = info['position'].copy(); wp = info['waypoint'].copy()
        for t in range(200):
            aim = wp + ahead * (wp - wb)
            best = None
            for a in A:
                d = np.linalg.norm(sim_path(env, a, h) - aim, axis=1)
                c = d.min() if cost == 'min' else d.mean()
                if best is None or c < best[0]: best = (c, a)
            obs, r, term, trunc, info = env.step(best[1]); ret += r
            if term: break
            if np.any(info['waypoint'] != wp): wb, wp = wp, info['waypoint'].copy()
        rets.append(ret)
    return np.array(rets)


for h in (4, 8, 16, 32):
    for cost in COSTS:
        r = drive(h, cost, range(6)); print(h, cost, r.mean().round(2), r.round(1), flush=True)
