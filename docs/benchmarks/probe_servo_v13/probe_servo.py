"""Experiment: would a servo candidate in the label probe tell never-paying bodies from paying ones?
For each body and seed: the probe as a run makes it (frames' and shooting horizons' simulated candidates, zero
action), plus the servo's simulated candidate (its forward model trained on the probe's data). Prints JSON lines."""
import json, sys
import numpy as np
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
from shaped_es.guides.clone_probe import clone_rounds_many
from shaped_es.shaping.forward_servo import ServoLabels, servo_model
from shaped_es import seeding

env, seeds = sys.argv[1], [int(s) for s in sys.argv[2].split(',')]
for seed in seeds:
    cfg = build_config({"env": env, "method": "shaped", "seed": seed, "executor": "inline"})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pos_dim = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
    mcfg = mphi_config(cfg, pos_dim)
    res = lp.probe(cfg, spec, pos_dim, mcfg)
    x0 = spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
    data, _ = lp.collect(cfg, spec, x0)
    m = servo_model(spec.obs_dim, pos_dim, spec.act_dim, mcfg, seeding.derive_seed(seed, seeding.SHAPING, 777))
    for trs in data:
        m.add(trs); m.train()
    sv = ServoLabels(m)
    ep_seeds = np.array([seeding.derive_seed(cfg.seed, seeding.SHAPING, lp.PROBE_KEY, 1000 + e) for e in range(lp.EPISODES)])
    flat = [t for g in data for t in g]
    (r, n), = clone_rounds_many(cfg, spec, x0, flat, [sv], ep_seeds, [99])
    zero = np.array(res.zero_action)
    def z(v):
        g, se = lp.paired(np.array(v), zero)
        return round(g / se, 2) if se > 0 else (np.inf if g > 0 else 0.0)
    out = {"env": env, "seed": seed, "frames": {k: z(v) for k, v in res.clones.items()},
           "shoot": {k: z(v) for k, v in (res.shoot_tried or ({str(res.shoot_horizon): res.shoot} if res.shoot else {})).items()},
           "servo": z(r), "chosen": lp.variant_name(res.frame, res.query_clip)}
    print(json.dumps(out), flush=True)
