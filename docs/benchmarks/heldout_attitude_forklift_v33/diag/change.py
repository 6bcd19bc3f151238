"""M_phi with the velocity change as its displacement input: state' = [s, dp_prev], displacement' = dp - dp_prev
(training) and q - dp_prev (query). Held-out action R^2 against the plain M_phi, and (attitude) the return its
labels drive."""
import sys
import numpy as np, gymnasium as gym
argv = sys.argv[1:]
sys.argv = [sys.argv[0], "x", "1"]
exec(open("fit.py").read().split("eid = sys.argv[1]")[0])

def prev_disp(tr):
    p = tr.position.astype(np.float64)
    d = np.zeros_like(p); same = np.r_[False, tr.episode[1:] == tr.episode[:-1]]
    d[1:][same[1:]] = (p[1:] - p[:-1])[same[1:]]
    return d  # (N, d): p_t - p_{t-1} (0 at an episode's first step)

def pairs(tr, change):
    s = tr.state.astype(np.float64); p = tr.position.astype(np.float64)
    nxt = np.r_[tr.episode[1:] == tr.episode[:-1], False]
    dp = np.zeros_like(p); dp[:-1] = p[1:] - p[:-1]
    prev = prev_disp(tr)
    if change:
        return np.c_[s, prev][nxt], (dp - prev)[nxt], tr.action[nxt]
    return s[nxt], dp[nxt], tr.action[nxt]

eid = argv[0]; steps = [int(x) for x in argv[1].split(",")]
env = gym.make(eid)
period = np.array([0, 0, 2 * np.pi]) if "Attitude" in eid else None
data = [collect(env, 100 + g, 16, period=period) for g in range(2)]
test = collect(env, 999, 16, period=period)
od, pd, ad = data[0].state.shape[1], data[0].position.shape[1], data[0].action.shape[1]
for change in (False, True):
    out = []
    for total in steps:
        cfg = InverseDynamicsConfig(frame="world", targets="one_step", min_return=-1e9, seed=0)
        m = InverseDynamics(od + pd * change, pd, ad, cfg)
        for tr in data:
            s, d, a = pairs(tr, change)
            x = np.c_[s, d].astype(np.float32)
            m.norm.update(x); m._append(x, a.astype(np.float32))
        m.train(total)
        s, d, y = pairs(test, change)
        lab = m.label(s.astype(np.float32), d.astype(np.float32))
        out.append(1 - ((lab - y) ** 2).sum() / ((y - y.mean(0)) ** 2).sum())
    print(f"{eid:22s} change={change!s:5s} R2 at {steps}: " + " ".join(f"{v:.3f}" for v in out), flush=True)
