import sys, numpy as np
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.guides import label_probe as lp
from shaped_es.guides.clone_probe import clone_rounds
from shaped_es.shaping.forward_shoot import shoot_model, ShootLabels
from shaped_es.shaping.forward_servo import servo_model, ServoLabels
import shaped_es.shaping.forward_shoot as FS
env_id = sys.argv[1]; seeds = [int(s) for s in sys.argv[2].split(",")]
TR = int(sys.argv[4]) if len(sys.argv) > 4 else 1
hs = [int(h) for h in sys.argv[3].split(",")] if len(sys.argv) > 3 else [4]
res = {}
for seed in seeds:
    cfg = build_config({"env": env_id, "method": "shaped", "seed": seed})
    ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pd = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
    mc = mphi_config(cfg, pd)
    x0 = spec.init(seeding.derive_seed(cfg.seed, seeding.INIT))
    data, steps = lp.collect(cfg, spec, x0)
    ev = np.array([seeding.derive_seed(cfg.seed, seeding.SHAPING, lp.PROBE_KEY, 1000 + e) for e in range(lp.EPISODES)])
    z, _ = lp.drive(cfg, lambda s, q: np.zeros((s.shape[0], spec.act_dim), np.float32), "world", ev)
    res.setdefault("zero", []).extend(z)
    variants = [("servo", None)] + [(f"shoot{h}", h) for h in hs]
    for name, h in variants:
        if h is None:
            m = servo_model(spec.obs_dim, pd, spec.act_dim, mc, 5); lab = ServoLabels(m)
        else:
            m = shoot_model(spec.obs_dim, pd, spec.act_dim, mc, 5)
            m.__init__(spec.obs_dim, pd, spec.act_dim, m.config, horizon=h); lab = ShootLabels(m)
        for trs in data:
            m.add(trs)
            for _ in range(TR): m.train()
        r, _ = lp.drive(cfg, lab, "world", ev)
        c, _ = clone_rounds(cfg, spec, x0, [t for g in data for t in g], lab, ev, 0)
        res.setdefault(name, []).extend(r); res.setdefault(name + "_clone", []).extend(c)
print(env_id, " ".join(f"{k} {np.mean(v):.2f}" for k, v in res.items()), flush=True)
