"""Servo labels through a plain forward MLP f(s, a) -> dp (tanh hidden), G by finite differences at a=0."""
import sys; sys.path.insert(0, str(__import__("pathlib").Path(__file__).resolve().parents[1] / "labels_offline"))
import numpy as np, gymnasium as gym, torch, time
torch.set_num_threads(1)
from probe import collect, closed_loop
from shaped_es.policies import MLPSpec
env_id = sys.argv[1]; gens = int(sys.argv[2]) if len(sys.argv) > 2 else 5
env = gym.make(env_id); spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0])
data = collect(env_id, spec, gens=gens)
S, A, D, Q = [], [], [], []
for trs in data:
    for t in trs:
        m, nxt = t.next_position()
        S.append(t.state[m]); A.append(t.action[m]); D.append((nxt - t.position)[m]); Q.append((t.waypoint - t.position)[m])
S, A, D, Q = (np.concatenate(x).astype(np.float32) for x in (S, A, D, Q))
ms = np.linalg.norm(D, axis=1).mean(); mq = np.median(np.linalg.norm(Q, axis=1))
print(env_id, "rows", len(S), "mean step %.4f median |w-p| %.4f" % (ms, mq))
X = np.concatenate([S, A], 1); mu, sd = X.mean(0), X.std(0) + 1e-6
d, na = D.shape[1], A.shape[1]
torch.manual_seed(0)
net = torch.nn.Sequential(torch.nn.Linear(X.shape[1], 64), torch.nn.Tanh(), torch.nn.Linear(64, 64), torch.nn.Tanh(), torch.nn.Linear(64, d))
opt = torch.optim.Adam(net.parameters(), 1e-3)
Xt, Dt = torch.tensor((X - mu) / sd), torch.tensor(D / ms)
t0 = time.time()
for it in range(int(sys.argv[3]) if len(sys.argv) > 3 else 3000):
    i = torch.randint(0, len(Xt), (256,))
    loss = ((net(Xt[i]) - Dt[i]) ** 2).mean(); opt.zero_grad(); loss.backward(); opt.step()
with torch.no_grad():
    r2 = 1 - ((net(Xt) - Dt) ** 2).sum() / ((Dt - Dt.mean(0)) ** 2).sum()
print("fit %.1fs R2 %.3f" % (time.time() - t0, r2))
print("controller", closed_loop(env_id, lambda st, o, i, p, w, pr, c: c.waypoint_controller(st, o, i)) if hasattr(gym.make(env_id).unwrapped, "waypoint_controller") or True else None)
print("zero", closed_loop(env_id, lambda st, o, i, p, w, pr, c: np.zeros((o.shape[0], spec.act_dim))))
def f(s, a):
    x = (np.concatenate([s, a], 1) - mu) / sd
    with torch.no_grad():
        return net(torch.tensor(x, dtype=torch.float32)).numpy().astype(np.float64)
def servo(k, damp):
    def fn(st, o, i, p, w, pr, c):
        B = o.shape[0]; z = np.zeros((B, na), np.float32)
        g = f(o, z)
        G = np.stack([f(o, z + 0.5 * np.eye(na, dtype=np.float32)[j]) - g for j in range(na)], -1)  # (B, d, act)
        G = G / np.linalg.norm(G, axis=(1, 2), keepdims=True)
        e = ((w - p) - damp * ms * g) / mq
        return k * (np.swapaxes(G, 1, 2) @ e[..., None])[..., 0]
    return fn
for damp in (0.0, 1.0, 3.0):
    print("damp", damp, [round(closed_loop(env_id, servo(k, damp))[0], 2) for k in (0.1, 0.2, 0.3, 0.5, 1.0)], flush=True)
