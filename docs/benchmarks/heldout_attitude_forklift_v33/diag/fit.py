"""M_phi (the run's one-step world-frame model) on a second-order body: held-out action R^2 by training steps,
and the return its labels drive (query clipped to c x the mean training step)."""
import sys, time
import numpy as np, gymnasium as gym
sys.path.insert(0, "/work/exp/s36/attitude"); sys.path.insert(0, "/work/main/docs/benchmarks/ego_shoot_v32")
import attitude  # noqa
import shaped_es.envs  # noqa
from shaped_es.data import Transitions
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.settings import InverseDynamicsConfig

def collect(env, seed, n_eps, T=200, period=None):
    rng = np.random.default_rng(seed)
    rows = {k: [] for k in ("episode", "step", "state", "position", "waypoint", "action", "reward")}
    lo, hi = env.action_space.low, env.action_space.high
    for e in range(n_eps):
        obs, info = env.reset(seed=int(rng.integers(1 << 30)))
        obs = np.asarray(obs, np.float64).ravel(); od, ad = obs.shape[0], env.action_space.shape[0]
        W = rng.normal(0, 1.0 / np.sqrt(od), (ad, od)); b = rng.normal(0, 0.5, ad)
        prev = None
        for t in range(T):
            a = np.clip(np.tanh(W @ obs + b) + rng.normal(0, 0.3, ad), -1, 1) if e % 2 else rng.uniform(-1, 1, ad)
            pos = np.ravel(info["position"]).astype(np.float64); wp = np.ravel(info["waypoint"]).astype(np.float64)
            if period is not None and prev is not None:  # unwrap like the run
                dd = pos - prev
                P = np.where(period > 0, period, 1.0)
                dd = np.where(period > 0, (dd + P / 2) % P - P / 2, dd)
                pos = prev + dd
            prev = pos
            for k, v in (("episode", e), ("step", t), ("state", obs), ("position", pos), ("waypoint", wp), ("action", a)):
                rows[k].append(v)
            obs, r, term, trunc, info = env.step(lo + (a + 1) / 2 * (hi - lo)); rows["reward"].append(r)
            obs = np.asarray(obs, np.float64).ravel()
            if term or trunc: break
    f = lambda k, dt: np.asarray(rows[k], dt)
    return Transitions(0, 0, f("episode", np.int32), f("step", np.int32), f("state", np.float32),
                       f("position", np.float32), f("waypoint", np.float32), f("action", np.float32), f("reward", np.float32))

def r2(m, tr):
    x, y = m.training_pairs(tr) if hasattr(m, "training_pairs") else (None, None)
    return x, y

eid = sys.argv[1]; steps_list = [int(s) for s in sys.argv[2].split(",")]
hidden = tuple(int(h) for h in sys.argv[3].split(",")) if len(sys.argv) > 3 else (20, 20)
env = gym.make(eid)
period = np.array([0, 0, 2 * np.pi]) if "Attitude" in eid else None
data = [collect(env, 100 + g, 16, period=period) for g in range(2)]
test = collect(env, 999, 16, period=period)
pd = data[0].position.shape[1]
from shaped_es.shaping.mphi_inputs import training_pairs
for total in steps_list:
    cfg = InverseDynamicsConfig(frame="world", targets="one_step", min_return=-1e9, seed=0, hidden=hidden, lr=float(sys.argv[4]) if len(sys.argv) > 4 else 1e-3)
    m = InverseDynamics(data[0].state.shape[1], pd, data[0].action.shape[1], cfg)
    m.add(data); t0 = time.time(); m.train(total)
    s = test.state; d = test.position[1:] - test.position[:-1]
    same = test.episode[1:] == test.episode[:-1]
    lab = m.label(s[:-1][same], d[same]); y = test.action[:-1][same]
    r2v = 1 - ((lab - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum()
    print(f"{eid} hidden {hidden} steps {total}: held-out action R2 {r2v:.3f} ({time.time()-t0:.1f}s)", flush=True)
