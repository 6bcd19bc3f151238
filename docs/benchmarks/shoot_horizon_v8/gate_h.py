import sys, numpy as np, importlib
for m in (sys.argv[3].split(",") if len(sys.argv) > 3 else []): importlib.import_module(m)
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
for env_id in sys.argv[1].split(","):
    out = []
    a2 = sys.argv[2] if len(sys.argv) > 2 else "10"
    lo, hi = (int(a2.split("-")[0]), int(a2.split("-")[1]) + 1) if "-" in a2 else (0, int(a2))
    for seed in range(lo, hi):
        cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
        ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
        spec, pd = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
        r = lp.probe(cfg, spec, pd, mphi_config(cfg, pd))
        out.append((seed, r.shoot_on, r.shoot_horizon, {k: round(float(np.mean(v)), 2) for k, v in r.shoot_tried.items()}, round(float(np.mean(r.zero_action)), 2)))
    on = [o for o in out if o[1]]
    print(env_id, len(on), "/", len(out), "on;", "changed (h != 4 and on):", [o[0] for o in out if o[1] and o[2] != 4], flush=True)
    for o in out: print("   ", o, flush=True)
