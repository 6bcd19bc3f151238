"""The probe's shooting clone at several horizons (what the probe would see), against zero action."""
import sys, numpy as np, importlib
from dataclasses import replace
for m in (sys.argv[4].split(",") if len(sys.argv) > 4 else []): importlib.import_module(m)
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
from shaped_es.guides.clone_probe import shoot_clone
env_id = sys.argv[1]; seeds = [int(s) for s in sys.argv[2].split(",")]
hs = [int(h) for h in sys.argv[3].split(",")]
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
    rs = {}
    for h in hs:
        c = build_config({"env": env_id, "method": "shaped", "seed": seed, "shaping": {"inverse_dynamics": {"shoot_horizon": h}}})
        r, n = shoot_clone(c, spec, x0, data, pd, mc, ev, 4)
        rs[h] = r
        out.append(f"h{h} {np.mean(r):.2f}{'*' if lp.beats(r, z)[0] else ''}")
    b = hs[0]
    for h in hs[1:]:
        out.append(f"{h}>{b}:{'Y' if lp.beats(rs[h], rs[b])[0] else 'n'}")
    print(env_id, seed, " ".join(out), flush=True)
