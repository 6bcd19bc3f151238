"""Kart: what limits the learned shooting labels? label-driven returns by model training budget / width."""
import sys, time, numpy as np
from dataclasses import replace
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
from shaped_es.shaping.forward_shoot import ShootLabels, shoot_model
env_id = sys.argv[1]; seeds = [int(s) for s in sys.argv[2].split(",")]
variants = sys.argv[3].split(",")  # e.g. s1500_h20,s6000_h20,s6000_h64
H = int(sys.argv[4]) if len(sys.argv) > 4 else 4
res = {}
for seed in seeds:
    cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pd = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
    mc = mphi_config(cfg, pd)
    x0 = spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
    data, steps = lp.collect(cfg, spec, x0)
    ev = np.array([seeding.derive_seed(cfg.seed, seeding.SHAPING, lp.PROBE_KEY, 1000 + e) for e in range(20)])
    z, _ = lp.drive(cfg, lambda s, q: np.zeros((s.shape[0], spec.act_dim), np.float32), "world", ev)
    line = [f"zero {z.mean():.2f}"]
    for v in variants:
        parts = dict((p[0], p[1:]) for p in v.split("_"))
        total, width = int(parts["s"]), int(parts["h"])
        m = shoot_model(spec.obs_dim, pd, spec.act_dim, replace(mc, hidden=(width, width)), H)
        t0 = time.time()
        for trs in data:
            m.add(trs)
        m.train(total)
        r, _ = lp.drive(cfg, ShootLabels(m), "world", ev)
        res.setdefault(v, []).append(r.mean() - z.mean())
        line.append(f"{v} {r.mean():.2f} ({time.time()-t0:.1f}s)")
    print(env_id, seed, " | ".join(line), flush=True)
for v, g in res.items():
    print("MEAN gain over zero", v, np.mean(g).round(2))
