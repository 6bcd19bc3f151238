"""Held-out action R^2 of a one-step world-frame M_phi whose displacement input is the k-th difference of the
position at the step (k = 1: plain; 2: the step's change from the last, step_change; 3: the change of that),
with the lower differences at t as extra state inputs. Random and random-linear policies' steps (fit.py's
collect), 2 x 16 episodes to fit, 16 held out; 1000 Adam steps as a probe's.
    python order_r2.py ENV_ID [ENV_ID ...]"""
import sys
import numpy as np, gymnasium as gym
sys.path[:0] = [".", "../heldout_crane_v34", "../heldout_attitude_forklift_v33/attitude"]
import attitude, crane, plate  # noqa: F401
import shaped_es.envs  # noqa: F401
exec(open("/work/main/docs/benchmarks/heldout_attitude_forklift_v33/diag/fit.py").read().split("def r2(")[0]
     .replace('sys.path.insert(0, "/work/exp/s36/attitude"); ', "").replace("import attitude  # noqa\n", ""))


def diffs(tr, k):
    """(N, k, d): the j-th difference of the position ending at each step (j = 1..k), NaN where the episode is
    too short; and (N,) whether the next step is in the same episode."""
    p = tr.position.astype(np.float64)
    n, d = p.shape
    out = np.full((n, k, d), np.nan)
    cur = p.copy()
    for j in range(k):
        nxt = np.full_like(cur, np.nan)
        same = tr.episode[1:] == tr.episode[:-1]
        nxt[1:][same] = (cur[1:] - cur[:-1])[same]
        out[:, j] = nxt
        cur = nxt
    return out


def pairs(tr, k):
    s = tr.state.astype(np.float64)
    D = diffs(tr, k)  # (N, k, d): differences ending at t
    nxt_same = np.r_[tr.episode[1:] == tr.episode[:-1], False]
    Dn = np.full_like(D, np.nan); Dn[:-1] = D[1:]  # differences ending at t + 1
    target = Dn[:, k - 1]  # (N, d): the k-th difference ending at t + 1
    extra = D[:, : k - 1].reshape(len(s), -1)  # (N, (k-1) d): the lower differences at t
    ok = nxt_same & np.isfinite(target).all(1) & np.isfinite(extra).all(1)
    return np.c_[s, extra][ok], target[ok], tr.action[ok]


for eid in sys.argv[1:]:
    env = gym.make(eid)
    period = np.array([0, 0, 2 * np.pi]) if "Attitude" in eid else None
    data = [collect(env, 100 + g, 16, period=period) for g in range(2)]
    test = collect(env, 999, 16, period=period)
    od, pd, ad = data[0].state.shape[1], data[0].position.shape[1], data[0].action.shape[1]
    out = []
    for k in (1, 2, 3):
        cfg = InverseDynamicsConfig(frame="world", targets="one_step", min_return=-1e9, seed=0)
        m = InverseDynamics(od + pd * (k - 1), pd, ad, cfg)
        for tr in data:
            s, d, a = pairs(tr, k)
            x = np.c_[s, d].astype(np.float32); m.norm.update(x); m._append(x, a.astype(np.float32))
        m.train(1000)
        s, d, y = pairs(test, k)
        lab = m.label(s.astype(np.float32), d.astype(np.float32))
        out.append(1 - ((lab - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum())
    print(f"{eid:16s} held-out action R2, order 1 / 2 / 3: " + " / ".join(f"{v:.3f}" for v in out), flush=True)
