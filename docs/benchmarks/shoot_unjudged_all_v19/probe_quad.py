import sys, json, numpy as np
sys.path.insert(0, __import__('os').path.dirname(__import__('os').path.abspath(__file__)))
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides.label_probe import probe
env=sys.argv[1]; kind=sys.argv[2]
for seed in [int(x) for x in sys.argv[3].split(',')]:
    cfg = build_config({"env": env, "method": "shaped", "seed": seed, "executor": "inline",
                        "shaping": {"inverse_dynamics": {"shoot_model": kind}}})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pos_dim = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
    res = probe(cfg, spec, pos_dim, mphi_config(cfg, pos_dim))
    print(env, kind, seed, 'shoot', {k: round(float(np.mean(v)),2) for k,v in res.shoot_tried.items()}, 'zero', np.mean(res.zero_action), 'on', res.shoot_on, res.shoot_horizon, 'cand', res.candidate, '%.1fs'%res.seconds, flush=True)
