"""Run the label probe of ENV on SEEDS for each probe_keep in KEEPS (0: the full probe), with inverse_dynamics settings
EXTRA (JSON), and print one JSON line per probe: its cost and what it decided (frame, clip, chunk, the shooting
rival's verdict and horizon, generation 0's candidate, whether it could judge, the extra horizons that run where it
cannot (``third``: its meaning changed during the study, the decisions do not depend on it), each horizon's mean).

    python probe_run.py ENV SEEDS KEEPS [EXTRA]     e.g. probe_run.py UR5Reach-v0 0,1,2 0,6 '{"shoot_probe_horizons":[8,16]}'
"""
import importlib, json, sys, time
import numpy as np
from shaped_es.config import build_config
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.label_probe import probe

env, seeds, keeps = sys.argv[1], [int(s) for s in sys.argv[2].split(",")], [int(k) for k in sys.argv[3].split(",")]
extra = json.loads(sys.argv[4]) if len(sys.argv) > 4 else {}
if ":" in env:
    importlib.import_module(env.split(":")[0])
for seed in seeds:
    for k in keeps:
        idc = {"probe_keep": k, **extra}
        cfg = build_config({"env": env, "method": "shaped", "seed": seed, "executor": "inline",
                            "shaping": {"inverse_dynamics": idc}})
        ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
        spec, pos_dim = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
        t = time.perf_counter()
        r = probe(cfg, spec, pos_dim, mphi_config(cfg, pos_dim))
        sims = {**r.clones, **{f"shoot:{h}": v for h, v in r.shoot_tried.items()}}
        out = dict(env=env, seed=seed, keep=k, extra=extra, steps=r.env_steps, sec=round(time.perf_counter() - t, 2),
                   frame=r.frame, clip=r.query_clip, chunk=r.chunk, shoot_on=r.shoot_on, horizon=r.shoot_horizon,
                   candidate=r.candidate, unjudged=r.unjudged(), third=r.third_horizon(), base=r.keeps_base(),
                   cand_mean=float(np.mean(sims[r.candidate])) if r.candidate in sims else None,
                   zero=float(np.mean(r.zero_action)),
                   tried={h: round(float(np.mean(v)), 2) for h, v in r.shoot_tried.items()})
        print(json.dumps(out), flush=True)
