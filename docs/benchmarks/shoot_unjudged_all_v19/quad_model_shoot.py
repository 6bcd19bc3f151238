"""Held-action shooting on Quad2D-v0 through learned models, trained on the label probe's data:
(a) the framework's chunk model (ForwardChunk, h-step displacement from s and the mean action);
(b) a one-step model f(s, a) -> (s' - s, p' - p) rolled out h steps with the action held."""
import sys, numpy as np, torch, time
sys.path.insert(0, __import__('os').path.dirname(__import__('os').path.abspath(__file__)))
import quad2d
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides.label_probe import collect
from shaped_es import seeding
import itertools
torch.set_num_threads(1)
seed = int(sys.argv[1]) if len(sys.argv) > 1 else 0
H = int(sys.argv[2]) if len(sys.argv) > 2 else 16
cfg = build_config({"env": "quad2d:Quad2D-v0", "method": "shaped", "seed": seed, "executor": "inline"})
ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
spec, d = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
x0 = seeding.initial_mean(spec, seed)
data, steps = collect(cfg, spec, x0)
S, A, S2, DP = [], [], [], []
for g in data:
    for tr in g:
        m, nxt = tr.next_position()
        idx = np.where(m)[0]
        S.append(tr.state[idx]); A.append(tr.action[idx]); S2.append(tr.state[idx + 1]); DP.append(nxt[idx] - tr.position[idx])
S, A, S2, DP = map(np.concatenate, (S, A, S2, DP))
print('probe data rows', len(S), 'env steps', steps, flush=True)
X = np.concatenate([S, A], 1); Y = np.concatenate([S2 - S, DP], 1)
xm, xs = X.mean(0), X.std(0) + 1e-6; ym, ys = Y.mean(0), Y.std(0) + 1e-6
net = torch.nn.Sequential(torch.nn.Linear(X.shape[1], 64), torch.nn.Tanh(), torch.nn.Linear(64, 64), torch.nn.Tanh(), torch.nn.Linear(64, Y.shape[1]))
opt = torch.optim.Adam(net.parameters(), 1e-3)
Xt = torch.tensor((X - xm) / xs, dtype=torch.float32); Yt = torch.tensor((Y - ym) / ys, dtype=torch.float32)
t0 = time.time()
for it in range(3000):
    i = torch.randint(0, len(Xt), (256,))
    loss = ((net(Xt[i]) - Yt[i]) ** 2).mean(); opt.zero_grad(); loss.backward(); opt.step()
print('fit loss %.4f in %.1f s' % (loss.item(), time.time() - t0), flush=True)
vals = np.linspace(-1, 1, 5); CAND = np.array(list(itertools.product(vals, vals)), np.float32)
def model_paths(s, h):
    """(K, h, 2) predicted displacements from s with each candidate held."""
    K = len(CAND); st = np.repeat(s[None], K, 0).astype(np.float32); p = np.zeros((K, 2)); out = []
    with torch.no_grad():
        for _ in range(h):
            x = torch.tensor((np.concatenate([st, CAND], 1) - xm) / xs, dtype=torch.float32)
            y = net(x).numpy() * ys + ym
            st = st + y[:, :-2]; p = p + y[:, -2:]; out.append(p.copy())
    return np.stack(out, 1)
def drive(h, seeds, ahead=1.0):
    rets = []
    for s in seeds:
        env = quad2d.Quad2D(); obs, info = env.reset(seed=int(s)); ret = 0; wb = info['position'].copy(); wp = info['waypoint'].copy()
        for t in range(200):
            aim = wp + ahead * (wp - wb) - info['position']
            P = model_paths(obs, h); c = np.linalg.norm(P - aim, axis=2).mean(1)
            obs, r, term, trunc, info = env.step(CAND[c.argmin()]); ret += r
            if term: break
            if np.any(info['waypoint'] != wp): wb, wp = wp, info['waypoint'].copy()
        rets.append(ret)
    return np.array(rets)
for h in (8, 16, 24):
    r = drive(h, range(100, 106)); print('one-step model rollout h', h, r.mean().round(2), r.round(1), flush=True)
