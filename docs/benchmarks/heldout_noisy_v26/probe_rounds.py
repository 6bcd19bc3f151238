"""The drive's simulated candidates with more DAgger rounds (clone_probe.ROUNDS, 3 by default)."""
import sys
import numpy as np
import noisy_bodies  # noqa: F401
import shaped_es.guides.clone_probe as cp
from shaped_es.config import build_config
from shaped_es.rollout import policy_spec, probe_env
from shaped_es.guides.shaped_setup import waypoint_dim, mphi_config
from shaped_es.guides.label_probe import probe
for rounds in (3, 6, 10):
    cp.ROUNDS = rounds
    out = []
    for seed in range(3):
        cfg = build_config({"env": sys.argv[1], "method": "shaped", "seed": seed})
        ep = probe_env(cfg.env, cfg.env_kwargs, reset=True)
        spec, pos = policy_spec(cfg, ep), waypoint_dim(cfg, ep)
        res = probe(cfg, spec, pos, mphi_config(cfg, pos))
        c = {k: float(np.mean(v)) for k, v in res.clones.items()}
        best = max(c, key=c.get)
        out.append((round(c.get("both", np.nan), 2), best, round(c[best], 2)))
    print(rounds, out, flush=True)
