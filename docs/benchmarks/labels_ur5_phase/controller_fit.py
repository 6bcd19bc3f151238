"""How well a policy-sized MLP can imitate UR5Reach-v0's waypoint controller from what the policy sees.

Rolls the controller (with action noise 0.3, to spread the states) on 256 episodes, fits a tanh MLP
(32, 32) by 4000 Adam steps of 256 rows to its actions from (a) the observation, (b) the observation
plus the waypoint displacement the controller reads, on the default env and with ``observe_phase``,
and prints the held-out squared error (sum over the 5 joints) on 256 other episodes.
Run: ``python docs/benchmarks/labels_ur5_phase/controller_fit.py`` (~2 min on 2 cores).
"""

import numpy as np
import torch

from shaped_es.envs.ur5.config import make_config
from shaped_es.envs.ur5.core import UR5Core


def collect(phase: bool, n: int = 256, noise: float = 0.3, seed: int = 0):
    core = UR5Core(make_config(observe_phase=phase))
    rng = np.random.default_rng(seed)
    st, obs, info = core.reset(np.arange(n) + 1000 * seed)
    X, W, Y = [], [], []
    while not st.done.all():
        a = core.waypoint_controller(st, obs, info)  # (n, 5)
        live = ~st.done
        X.append(obs[live]), W.append((info["waypoint"] - info["position"])[live]), Y.append(a[live])
        st, obs, _, _, _, info = core.step(st, np.clip(a + noise * rng.standard_normal(a.shape), -1, 1))
    return (np.concatenate(v).astype(np.float32) for v in (X, W, Y))


def fit(x, y, xt, yt, hidden=(32, 32), steps=4000) -> float:
    torch.manual_seed(0)
    mu, sd = x.mean(0), x.std(0) + 1e-6
    layers, d = [], x.shape[1]
    for h in hidden:
        layers += [torch.nn.Linear(d, h), torch.nn.Tanh()]
        d = h
    net = torch.nn.Sequential(*layers, torch.nn.Linear(d, y.shape[1]), torch.nn.Tanh())
    opt = torch.optim.Adam(net.parameters(), 3e-3)
    X, Y = torch.tensor((x - mu) / sd), torch.tensor(y)
    for _ in range(steps):
        idx = torch.randint(0, len(X), (256,))
        loss = ((net(X[idx]) - Y[idx]) ** 2).sum(1).mean()
        opt.zero_grad(), loss.backward(), opt.step()
    with torch.no_grad():
        return float(((net(torch.tensor((xt - mu) / sd)) - torch.tensor(yt)) ** 2).sum(1).mean())


if __name__ == "__main__":
    for phase in (False, True):
        (x, w, y), (xt, wt, yt) = collect(phase, seed=0), collect(phase, seed=1)
        print(f"observe_phase={phase}: label variance {float(y.var(0).sum()):.4f}; held-out error from the "
              f"observation {fit(x, y, xt, yt):.4f}, from the observation + waypoint displacement "
              f"{fit(np.c_[x, w], y, np.c_[xt, wt], yt):.4f}")
