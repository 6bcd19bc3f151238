import sys; sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "labels_offline"))
import numpy as np, gymnasium as gym, torch, time
from probe import collect, closed_loop
from shaped_es.policies import MLPSpec
env_id = sys.argv[1]; gens = int(sys.argv[2]) if len(sys.argv) > 2 else 5
env = gym.make(env_id); spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
data = collect(env_id, spec, gens=gens)
S, A, D = [], [], []
for trs in data:
    for t in trs:
        m, nxt = t.next_position()
        S.append(t.state[m]); A.append(t.action[m]); D.append((nxt - t.position)[m])
S, A, D = (np.concatenate(x).astype(np.float32) for x in (S, A, D))
ms = np.linalg.norm(D, axis=1).mean(); print(env_id, "rows", len(S), "mean step", ms)
mu_s, sd_s = S.mean(0), S.std(0) + 1e-6
d, na = D.shape[1], A.shape[1]
torch.manual_seed(0)
net = torch.nn.Sequential(torch.nn.Linear(S.shape[1], 64), torch.nn.Tanh(), torch.nn.Linear(64, 64), torch.nn.Tanh(), torch.nn.Linear(64, d + d * na))
opt = torch.optim.Adam(net.parameters(), 1e-3)
St, At, Dt = torch.tensor((S - mu_s) / sd_s), torch.tensor(A), torch.tensor(D / ms)
def fwd(s):
    o = net(s); return o[:, :d], o[:, d:].reshape(-1, d, na)
t0 = time.time()
for it in range(3000):
    i = torch.randint(0, len(St), (256,))
    g, G = fwd(St[i]); pred = g + (G @ At[i][..., None])[..., 0]
    loss = ((pred - Dt[i]) ** 2).mean(); opt.zero_grad(); loss.backward(); opt.step()
with torch.no_grad():
    g, G = fwd(St); pred = g + (G @ At[..., None])[..., 0]
    r2 = 1 - ((pred - Dt) ** 2).sum() / ((Dt - Dt.mean(0)) ** 2).sum()
    r2g = 1 - ((g - Dt) ** 2).sum() / ((Dt - Dt.mean(0)) ** 2).sum()
print("fit %.1fs R2 %.3f (drift only %.3f)" % (time.time() - t0, r2, r2g))
print("controller", closed_loop(env_id, lambda st, o, i, p, w, pr, c: c.waypoint_controller(st, o, i)))
print("zero", closed_loop(env_id, lambda st, o, i, p, w, pr, c: np.zeros((o.shape[0], spec.act_dim))))
def servo(k, K, damp, scale):
    def f(st, o, i, p, w, pr, c):
        with torch.no_grad():
            gd, G = fwd(torch.tensor((o - mu_s) / sd_s, dtype=torch.float32))
        G = G.numpy().astype(np.float64); gd = gd.numpy().astype(np.float64)
        G = G / np.linalg.norm(G, axis=(1, 2), keepdims=True)
        e = K * (w - p) - damp * (ms * gd if DRIFT else (p - pr))
        if scale: e = e / ms
        return k * (np.swapaxes(G, 1, 2) @ e[..., None])[..., 0]
    return f

for DRIFT in (False, True):
    for damp in (2.0, 3.0, 5.0):
        print("drift" if DRIFT else "diff", damp, [round(closed_loop(env_id, servo(k, 1.0, damp, False))[0], 2) for k in (1.5, 2, 3, 5)], flush=True)
torch.save  # noqa
np.savez(str(__import__("pathlib").Path(__file__).with_name("fwd_%s.npz")) % env_id, mu_s=mu_s, sd_s=sd_s, ms=ms, **{f"p{i}": p.detach().numpy() for i, p in enumerate(net.parameters())})
