import sys, numpy as np
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
for env_id in sys.argv[1].split(","):
    out = []
    for seed in range(int(sys.argv[2]) if len(sys.argv) > 2 else 10):
        cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
        ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
        spec, pd = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
        r = lp.probe(cfg, spec, pd, mphi_config(cfg, pd))
        out.append((r.shoot_on, round(float(np.mean(r.shoot)), 2), round(float(np.mean(r.zero_action)), 2)))
    print(env_id, sum(o[0] for o in out), "/", len(out), "on;", out, flush=True)
