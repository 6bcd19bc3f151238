"""Offline: the shooting labels with a LEARNED chunk model on the drone, held actions, min vs mean cost,
trained on (a) noisy-hover babbling data, (b) the controller's steps with action noise. Labels drive the
body as a policy (the probe's first question); zero action returns 0.00, the controller 9.56."""
import sys
import numpy as np
sys.path.insert(0, str(__import__('pathlib').Path(__file__).resolve().parent.parent / 'heldout_drone_v16'))
import drone as D  # noqa: E402  (../heldout_drone_v16/drone.py)
from shaped_es.data import Transitions
from shaped_es.shaping.forward_shoot import ShootLabels, shoot_model
from shaped_es.shaping.settings import InverseDynamicsConfig

def collect(kind, episodes, rng, noise=0.3):
    trs = []
    for e in range(episodes):
        env = D.Drone(); obs, info = env.reset(seed=int(rng.integers(1 << 30)))
        S, P, W, A, R = [], [], [], [], []
        a_prev = np.zeros(2)
        for t in range(D.MAX_STEPS):
            if kind == "babble":
                a = np.clip(0.8 * a_prev + 0.2 * rng.normal(0, 0.6, 2), -1, 1); a_prev = a
            else:
                a = np.clip(env.waypoint_controller(obs, info) + rng.normal(0, noise, 2), -1, 1)
            S.append(obs); P.append(info["position"]); W.append(info["waypoint"]); A.append(a)
            obs, r, term, trunc, info = env.step(a); R.append(r)
            if term: break
        T = len(S)
        trs.append(Transitions(0, 0, np.zeros(T, np.int32), np.arange(T, dtype=np.int32), np.array(S, np.float32),
                               np.array(P, np.float32), np.array(W, np.float32), np.array(A, np.float32),
                               np.array(R, np.float32)))
    return trs

def drive(labels, episodes=8):
    out = []
    for s in range(episodes):
        env = D.Drone(); obs, info = env.reset(seed=1000 + s); R = 0.0
        for t in range(D.MAX_STEPS):
            err = (np.asarray(info["waypoint"]) - np.asarray(info["position"]))[None].astype(np.float32)
            a = labels(obs[None], err)[0]
            obs, r, term, trunc, info = env.step(a); R += r
            if term: break
        out.append(R)
    return np.mean(out), np.min(out), np.max(out)

rng = np.random.default_rng(0)
for kind in sys.argv[1].split(","):
    data = collect(kind, 60, rng)
    for h in (4, 8, 16):
        m = shoot_model(8, 2, 2, InverseDynamicsConfig(), h, seed=0)
        for i in range(0, len(data), 10):
            m.add(data[i:i + 10]); m.train()
        for cost in ("min", "mean"):
            print(kind, "h", h, cost, "labels drive: mean %.2f min %.2f max %.2f" % drive(ShootLabels(m, 0.0, cost)), flush=True)
