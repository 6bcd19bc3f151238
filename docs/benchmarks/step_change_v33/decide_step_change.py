"""The label probe's step_change choice (guides/probe_step_change.py) on each seed's probe data, without the rest of
the probe: which runs the auto rule turns on.   python decide_step_change.py SEEDS ENV [ENV ...]

A held-out body is named ``folder under docs/benchmarks:module:EnvId`` (its module imported from there)."""
import importlib, os, sys, time

import shaped_es.envs  # noqa: F401
from shaped_es import seeding
from shaped_es.config import build_config
from shaped_es.guides.probe_rollouts import collect
from shaped_es.guides.probe_step_change import decide
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.rollout import policy_spec, probe_env

B = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..") + "/"
seeds = [int(s) for s in sys.argv[1].split(",")]
for name in sys.argv[2:]:
    d, mod, eid = name.split(":") if name.count(":") == 2 else ("", "", name)
    if mod:
        sys.path.insert(0, B + d)
        importlib.import_module(mod)
        eid = f"{mod}:{eid}"
    out = []
    t0 = time.time()
    for seed in seeds:
        cfg = build_config({"env": eid, "method": "shaped", "seed": seed, "executor": "inline"})
        spec = policy_spec(cfg, probe_env(cfg.env, cfg.env_kwargs))
        pos_dim = waypoint_dim(cfg)
        data, _ = collect(cfg, spec, seeding.initial_mean(spec, seed))
        on, e = decide(cfg.shaping.inverse_dynamics, spec, pos_dim, data, mphi_config(cfg, pos_dim))
        out.append(f"{seed}:{'ON' if on else 'off'}({e.get('plain', float('nan')):.2f}/{e.get('change', float('nan')):.2f})")
    print(f"{eid:24s} " + " ".join(out) + f"  ({time.time() - t0:.0f} s)", flush=True)
