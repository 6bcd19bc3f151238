import sys, json, numpy as np
import noisy_bodies  # noqa
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import waypoint_dim, mphi_config
from shaped_es.guides.label_probe import probe
env = sys.argv[1]
for steps, lr in [(200, 3e-3), (600, 3e-3), (200, 1e-2), (1500, 3e-3)]:
    out = []
    for seed in range(3):
        cfg = build_config({"env": env, "method": "shaped", "seed": seed,
                            "shaping": {"mean_clone": {"steps": steps, "lr": lr}}})
        ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
        spec, pos = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
        res = probe(cfg, spec, pos, mphi_config(cfg, pos))
        c = {k: float(np.mean(v)) for k, v in res.clones.items()}
        lab = {k: float(np.mean(v)) for k, v in res.returns.items()}
        best = max(c, key=c.get)
        out.append((round(c.get("both", np.nan), 2), best, round(c[best], 2), round(max(lab.values()), 2),
                    {k: round(float(np.mean(v)), 2) for k, v in res.shoot_tried.items()} if hasattr(res, "shoot_tried") and isinstance(res.shoot_tried, dict) else None))
    print(steps, lr, out, flush=True)
