"""Experiment: behaviour cloning under the ES's own parameter noise (each step's gradient taken at
theta + s z, z ~ N(0, I)), patched into population_fit.fit_rows. CLONE_SIGMA env var (0: off)."""
import os, sys, time
import numpy as np
import shaped_es.shaping.population_fit as pf
from shaped_es.shaping.population_mlp import PopulationMLP, make_optimizer

SIG = float(os.environ.get("CLONE_SIGMA", "0"))
orig = pf.fit_rows

def fit_rows(task):
    if SIG <= 0 or task.steps <= 0:
        return orig(task)
    cpu0 = time.process_time()
    has, k_eval = np.asarray(task.has), task.k_eval
    S, A = task.arrays()
    net = PopulationMLP(task.spec, task.theta)
    P, B = net.flat.shape[0], S.shape[2]
    weight = has.astype(np.float32)
    s_eval = S[:k_eval].transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)
    a_eval = A[:k_eval].transpose(1, 0, 2, 3).reshape(P, k_eval * B, -1)
    acts = []
    def eval_mse():
        pred = net.forward(s_eval); acts.append(pred)
        mse = ((pred - a_eval) ** 2).mean((1, 2), dtype=np.float64)
        return np.where(has, mse, np.nan)
    before = eval_mse()
    rng = np.random.default_rng(int(abs(float(task.theta.ravel()[:8].sum())) * 1e6) % (2**32))
    if has.any():
        opt = make_optimizer(task.optimizer, net.flat.shape, task.lr)
        for k in range(task.steps):
            th = net.flat.copy()
            net.flat += (SIG * rng.standard_normal(net.flat.shape)).astype(np.float32)
            net.mse_backward(S[k], A[k], weight)
            net.flat[...] = th
            opt.step(net.flat, net.grad)
    after = eval_mse()
    return net.flat, before, after, acts[0], acts[1], time.process_time() - cpu0

pf.fit_rows = fit_rows
import shaped_es.shaping.cloning as cl
cl.fit_rows = fit_rows
import shaped_es.guides.clone_probe as cp
cp.fit_rows = fit_rows

if __name__ == "__main__":
    from shaped_es.cli import main as climain
    sys.argv = ["shaped-es"] + sys.argv[1:]
    sys.exit(climain())
