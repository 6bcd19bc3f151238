"""The label probe's held-out errors of the shooting labels' two frames (guides/probe_shoot_frame.py), per body and
seed, from the probe's own data generations (no probe rollouts beyond them): "world/waypoint" per seed.

    python decide_frames.py 0,1,2,3,4,5,6,7,8,9 PointVel-v0 heldout_trailer_v31:trailer:Trailer-v0 ...

A held-out body is named ``folder under docs/benchmarks:module:EnvId``."""
import os
import sys
import numpy as np
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.env_probe import probe_env
from shaped_es.rollout import policy_spec
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides.probe_rollouts import collect
from shaped_es.guides import probe_shoot_frame

B = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..") + "/"
seeds = [int(s) for s in sys.argv[1].split(",")]
for spec_ in sys.argv[2:]:
    if spec_.count(":") == 2:
        d, mod, eid = spec_.split(":"); sys.path.insert(0, B + d); env_id = f"{mod}:{eid}"
    else:
        env_id = spec_
    row = []
    for seed in seeds:
        cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
        ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
        spec, pos_dim = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
        data, _ = collect(cfg, spec, seeding.initial_mean(spec, cfg.seed))
        f, e = probe_shoot_frame.decide(cfg.shaping.inverse_dynamics, spec, pos_dim, data, mphi_config(cfg, pos_dim))
        row.append(f"{e['world']:.2f}/{e['waypoint']:.2f}" if e else "-")
    print(f"{env_id:22s} " + " ".join(row), flush=True)
