"""The label probe's seconds and env steps with and without the clip-4 variants, side by side (interleaved, 3
repeats per body, seed 0, inline): prints JSON, per body the medians and the ratio of medians.

    python docs/benchmarks/probe_clip_long_v16/probe_cost.py > probe_cost.json
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from shaped_es.config import build_config
from shaped_es.guides import label_probe
from shaped_es.guides.shaped_setup import mphi_config, waypoint_dim
from shaped_es.rollout import policy_spec, probe_env

BODIES = ("PointVel-v0", "Unicycle-v0", "UR5Reach-v0", "SwimmerWay-v0")


def once(env: str, long_clip: float | None) -> tuple[float, int]:
    cfg = build_config({"env": env, "method": "shaped", "seed": 0, "executor": "inline",
                        "shaping": {"inverse_dynamics": {"probe_clip_long": long_clip}}})
    probe = probe_env(cfg.env, cfg.env_kwargs, reset=True)
    spec, pos = policy_spec(cfg, probe), waypoint_dim(cfg, probe)
    t0 = time.perf_counter()
    res = label_probe.probe(cfg, spec, pos, mphi_config(cfg, pos))
    return time.perf_counter() - t0, res.env_steps


if __name__ == "__main__":
    out = {}
    for env in BODIES:
        once(env, 4.0)  # warm-up: kernels compiled, imports done
        rows = {None: [], 4.0: []}
        for _ in range(3):
            for c in (None, 4.0):
                rows[c].append(once(env, c))
        off, on = (np.array(rows[c]) for c in (None, 4.0))
        out[env] = {"seconds_median": {"off": float(np.median(off[:, 0])), "on": float(np.median(on[:, 0]))},
                    "env_steps": {"off": int(off[0, 1]), "on": int(on[0, 1])},
                    "seconds_ratio": float(np.median(on[:, 0]) / np.median(off[:, 0])),
                    "env_steps_ratio": float(on[0, 1] / off[0, 1])}
        print(env, out[env], file=sys.stderr)
    json.dump(out, sys.stdout, indent=1)
    print()
