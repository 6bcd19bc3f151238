import sys, numpy as np
sys.path.insert(0, __import__('os').path.dirname(__import__('os').path.abspath(__file__))); sys.path.insert(0, __import__('os').path.join(__import__('os').path.dirname(__import__('os').path.abspath(__file__)), '..', 'shoot_unjudged_v18'))
from drive_shoot import drive_shoot
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides.label_probe import collect, probe_seeds
from shaped_es.guides.clone_probe import shoot_labels
from shaped_es import seeding
env=sys.argv[1]; kind=sys.argv[2]; extra=int(sys.argv[4]) if len(sys.argv)>4 else 0
for seed in [int(x) for x in sys.argv[3].split(',')]:
    cfg = build_config({"env": env, "method": "shaped", "seed": seed, "executor": "inline", "shaping": {"inverse_dynamics": {"shoot_model": kind}}})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, d = policy_spec(cfg, ep), waypoint_dim(cfg, ep); mc = mphi_config(cfg, d)
    data, _ = collect(cfg, spec, seeding.initial_mean(spec, seed)); seeds = probe_seeds(cfg)
    out = {}
    for h in (8, 16):
        lab = shoot_labels(cfg, spec, data, d, mc, h)
        if extra: lab.model.train(extra)
        for c in ("min", "mean"):
            lab.cost = c; out[f"{h}{c}"] = drive_shoot(cfg, lab, seeds).mean()
    print(env, kind, seed, {k: round(float(v), 2) for k, v in out.items()}, flush=True)
