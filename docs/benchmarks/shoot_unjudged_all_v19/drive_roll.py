import sys, numpy as np
sys.path.insert(0, __import__('os').path.dirname(__import__('os').path.abspath(__file__))); sys.path.insert(0, __import__('os').path.join(__import__('os').path.dirname(__import__('os').path.abspath(__file__)), '..', 'shoot_unjudged_v18'))
from drive_shoot import drive_shoot, probe_setup
from shaped_es.guides.clone_probe import shoot_labels
env=sys.argv[1]; kind=sys.argv[2]; extra=int(sys.argv[4]) if len(sys.argv)>4 else 0
for seed in [int(x) for x in sys.argv[3].split(',')]:
    cfg, spec, d, mc, data, seeds = probe_setup(env, seed, {"shoot_model": kind})
    out = {}
    for h in (8, 16):
        lab = shoot_labels(cfg, spec, data, d, mc, h)
        if extra: lab.model.train(extra)
        for c in ("min", "mean"):
            lab.cost = c; out[f"{h}{c}"] = drive_shoot(cfg, lab, seeds).mean()
    print(env, kind, seed, {k: round(float(v), 2) for k, v in out.items()}, flush=True)
