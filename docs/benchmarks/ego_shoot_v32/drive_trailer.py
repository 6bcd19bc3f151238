"""The shooting labels driving the new user's car-and-trailer step by step, their chunk model in the world and in
the waypoint frame, fitted offline on random linear policies' steps (GENS x 20 episodes, STEPS Adam steps each):
the held-out error of each frame's paths and the mean return over 10 episodes (zero action 0.00; the held-action
labels with the simulator as their model 7.9 at 8 steps, ``../shoot_unjudged_all_v19/oracle_shoot.py``).

    python drive_trailer.py trailer:Trailer [h] [gens] [steps]        # HID=64,64 wider models; HOLD=8 held actions
"""
import importlib, os, sys, time
import numpy as np
from shaped_es.data import Transitions
from shaped_es.shaping.forward_shoot import ForwardChunk, ShootLabels
from shaped_es.shaping.settings import InverseDynamicsConfig
from shaped_es.shaping.frames import rotate

spec = sys.argv[1]; mod, _, cls = spec.partition(":")
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "heldout_trailer_v31"))
Env = getattr(importlib.import_module(mod), cls)
H = int(sys.argv[2]) if len(sys.argv) > 2 else 8
GENS = int(sys.argv[3]) if len(sys.argv) > 3 else 3
STEPS = int(sys.argv[4]) if len(sys.argv) > 4 else 500
HOLD = int(os.environ.get('HOLD', '0'))


def collect(seed, n_eps, T=200):
    rng = np.random.default_rng(seed); env = Env()
    rows = {k: [] for k in ("episode", "step", "state", "position", "waypoint", "action", "reward")}
    for e in range(n_eps):
        obs, info = env.reset(seed=int(rng.integers(1 << 30)))
        od, ad = obs.shape[0], env.action_space.shape[0]
        W = rng.normal(0, 1.0, (ad, od)); b = rng.normal(0, 0.5, ad)
        for t in range(T):
            if HOLD:
                if t % HOLD == 0: a = rng.uniform(-1, 1, ad)
            else:
                a = np.clip(np.tanh(W @ obs + b) + rng.normal(0, 0.3, ad), -1, 1)
            for k, v in (("episode", e), ("step", t), ("state", obs), ("position", info["position"]),
                         ("waypoint", info["waypoint"]), ("action", a)):
                rows[k].append(v)
            obs, r, term, trunc, info = env.step(a); rows["reward"].append(r)
            if term or trunc: break
    f = lambda k, dt: np.asarray(rows[k], dt)
    return Transitions(0, 0, f("episode", np.int32), f("step", np.int32), f("state", np.float32),
                       f("position", np.float32), f("waypoint", np.float32), f("action", np.float32), f("reward", np.float32))


def heldout_err(m, tr, waypoint):
    good = np.unique(tr.episode)
    x, y, q = m._pairs(tr, good)
    pred = m.predict(x[:, :m.obs_dim], x[:, m.obs_dim:]).reshape(len(x), -1)
    return float(((pred - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum())


def drive(labels, seeds, waypoint):
    env = Env(); rets = []
    for s in seeds:
        obs, info = env.reset(seed=int(s)); ret = 0.0; wb = info["position"].copy(); wp = info["waypoint"].copy()
        for t in range(200):
            err = (wp - info["position"]) + labels.ahead * (wp - wb)
            if waypoint:
                ang = np.arctan2(*(wp - info["position"])[::-1])
                err = rotate(err[None], np.array([ang]))[0]
            a = labels(obs[None].astype(np.float32), err[None].astype(np.float32))[0]
            obs, r, term, trunc, info = env.step(a); ret += r
            if term or trunc: break
            if np.any(info["waypoint"] != wp): wb, wp = wp, info["waypoint"].copy()
        rets.append(ret)
    return np.array(rets)


data = [collect(100 + g, 20) for g in range(GENS)]
test = collect(999, 20)
import os; HID = tuple(int(x) for x in os.environ.get("HID", "20,20").split(","))
cfg = InverseDynamicsConfig(hidden=HID, frame="world", targets="one_step", min_return=-1e9, seed=0)
for name, wf in (("world", False), ("waypoint", True)):
    m = ForwardChunk(data[0].state.shape[1], 2, data[0].action.shape[1], cfg, horizon=H, frame=name)
    t0 = time.time()
    for tr in data:
        m.add([tr]); m.train(STEPS)
    lab = ShootLabels(m, 1.0, "min")
    r = drive(lab, range(10), wf)
    print(f"{name:9s} h={H} nmse={heldout_err(m, test, wf):.3f} return {r.mean():.2f} {np.round(r, 1)} ({time.time()-t0:.0f}s)", flush=True)
