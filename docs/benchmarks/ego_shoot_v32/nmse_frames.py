"""The shooting labels' chunk model in the world and the waypoint frame, fitted on random linear policies' steps
(3 x 16 episodes, 500 Adam steps each) and scored on 16 more episodes: the share of the paths' variance each leaves
unexplained, at 4 and 16 steps.

    python nmse_frames.py PointVel-v0 heldout_trailer_v31:trailer:Trailer-v0 ...     # frame_errors.txt

A held-out body is named ``folder under docs/benchmarks:module:EnvId``."""
import importlib, os, sys, time
import numpy as np
import gymnasium as gym
import shaped_es.envs  # noqa
from shaped_es.data import Transitions
from shaped_es.shaping.forward_shoot import ForwardChunk
from shaped_es.shaping.settings import InverseDynamicsConfig

B = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..") + "/"


def collect(env, seed, n_eps, T=200):
    rng = np.random.default_rng(seed)
    rows = {k: [] for k in ("episode", "step", "state", "position", "waypoint", "action", "reward")}
    lo, hi = env.action_space.low, env.action_space.high
    for e in range(n_eps):
        obs, info = env.reset(seed=int(rng.integers(1 << 30)))
        obs = np.asarray(obs, np.float64).ravel()
        od, ad = obs.shape[0], env.action_space.shape[0]
        W = rng.normal(0, 1.0 / np.sqrt(od), (ad, od)); b = rng.normal(0, 0.5, ad)
        for t in range(T):
            a = np.clip(np.tanh(W @ obs + b) + rng.normal(0, 0.3, ad), -1, 1)
            for k, v in (("episode", e), ("step", t), ("state", obs), ("position", np.ravel(info["position"])),
                         ("waypoint", np.ravel(info["waypoint"])), ("action", a)):
                rows[k].append(v)
            obs, r, term, trunc, info = env.step(lo + (a + 1) / 2 * (hi - lo)); rows["reward"].append(r)
            obs = np.asarray(obs, np.float64).ravel()
            if term or trunc: break
    f = lambda k, dt: np.asarray(rows[k], dt)
    return Transitions(0, 0, f("episode", np.int32), f("step", np.int32), f("state", np.float32),
                       f("position", np.float32), f("waypoint", np.float32), f("action", np.float32), f("reward", np.float32))


def nmse(m, tr):
    x, y, q = m._pairs(tr, np.unique(tr.episode))
    pred = m.predict(x[:, :m.obs_dim], x[:, m.obs_dim:]).reshape(len(x), -1)
    return float(((pred - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum())


for spec in sys.argv[1:]:
    d, mod, eid = spec.split(":") if spec.count(":") == 2 else ("", "", spec)
    if mod:
        sys.path.insert(0, B + d); importlib.import_module(mod)
    env = gym.make(eid)
    t0 = time.time()
    data = [collect(env, 100 + g, 16) for g in range(3)]
    test = collect(env, 999, 16)
    pd = data[0].position.shape[1]
    if pd < 2:
        print(f"{eid}: pos_dim {pd}"); continue
    out = []
    for h in (4, 16):
        for frame in ("world", "waypoint"):
            cfg = InverseDynamicsConfig(frame="world", targets="one_step", min_return=-1e9, seed=0)
            m = ForwardChunk(data[0].state.shape[1], pd, data[0].action.shape[1], cfg, horizon=h, frame=frame)
            for tr in data:
                m.add([tr]); m.train(500)
            out.append(nmse(m, test))
    print(f"{eid:16s} h4 world {out[0]:.3f} wp {out[1]:.3f} | h16 world {out[2]:.3f} wp {out[3]:.3f} ({time.time()-t0:.0f}s)", flush=True)
