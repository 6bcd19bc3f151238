"""Held-action shooting on Quad2D-v0 with the simulator as the model: does the label form itself drive it?"""
import sys, copy, itertools, numpy as np
sys.path.insert(0, __import__('os').path.dirname(__import__('os').path.abspath(__file__)))
import hover
vals = np.linspace(-1, 1, 5)
A = np.array(list(itertools.product(vals, vals)))
def sim_path(env, a, h):
    e = copy.deepcopy(env); ps = []
    for _ in range(h):
        obs, r, term, trunc, info = e.step(a); ps.append(info['position'])
        if term: ps += [np.array([9.,9.])]*(h-len(ps)); break
    return np.array(ps)
def drive(h, cost, seeds, ahead=1.0):
    rets=[]
    for s in seeds:
        env = hover.Hover(); obs, info = env.reset(seed=int(s)); ret=0; wb=info['position'].copy(); wp=info['waypoint'].copy()
        for t in range(200):
            aim = wp + ahead*(wp-wb)
            best=None
            for a in A:
                P = sim_path(env, a, h); d = np.linalg.norm(P-aim, axis=1)
                c = d.min() if cost=='min' else d.mean()
                if best is None or c < best[0]: best=(c,a)
            obs, r, term, trunc, info = env.step(best[1]); ret += r
            if term: break
            if np.any(info['waypoint'] != wp): wb, wp = wp, info['waypoint'].copy()
        rets.append(ret)
    return np.array(rets)
seeds = range(6)
for h in (4, 8, 16, 32):
    for cost in ('mean', 'min'):
        r = drive(h, cost, seeds); print(h, cost, r.mean().round(2), r.round(1), flush=True)
