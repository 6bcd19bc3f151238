"""The label probe's simulated shooting candidate (what the probe sees) at several shoot_ahead values,
against zero action, on the probe's own data and episodes.

    python docs/benchmarks/shoot_ahead_v10/lab.py Kart-v0 0,1,2,3,4,5,6,7 0,1 4
    python docs/benchmarks/shoot_ahead_v10/lab.py UR5Reach-v0 0,1,2,3,4,5,6,7,8,9 0,1 4
"""
import sys, numpy as np, importlib
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
from shaped_es.guides.clone_probe import shoot_clone
for m in (sys.argv[5].split(",") if len(sys.argv) > 5 else []): importlib.import_module(m)
env_id = sys.argv[1]; seeds = [int(s) for s in sys.argv[2].split(",")]
aheads = [float(a) for a in sys.argv[3].split(",")]; h = int(sys.argv[4])
acc = {a: [] for a in aheads}
for seed in seeds:
    cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pd = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
    mc = mphi_config(cfg, pd)
    x0 = spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
    data, steps = lp.collect(cfg, spec, x0)
    ev = np.array([seeding.derive_seed(cfg.seed, seeding.SHAPING, lp.PROBE_KEY, 1000 + e) for e in range(lp.EPISODES)])
    z, _ = lp.drive(cfg, lambda s, q: np.zeros((s.shape[0], spec.act_dim), np.float32), "world", ev)
    out = [f"zero {np.mean(z):.2f}"]
    for a in aheads:
        c = build_config({"env": env_id, "method": "shaped", "seed": seed,
                          "shaping": {"inverse_dynamics": {"shoot_horizon": h, "shoot_ahead": a}}})
        r, n = shoot_clone(c, spec, x0, data, pd, mc, ev, 4)
        acc[a].append(np.mean(r) - np.mean(z))
        out.append(f"a{a:g} {np.mean(r):.2f}{'*' if lp.beats(r, z)[0] else ''}")
    print(env_id, seed, " ".join(out), flush=True)
print(env_id, "h", h, "mean gain over zero:", {a: round(float(np.mean(v)), 2) for a, v in acc.items()})
