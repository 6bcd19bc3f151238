"""Seconds per env step of a recorded and an unrecorded rollout through the Gymnasium loop (``rollout/gym_loop.py``),
two code versions side by side in one run: each repeat runs the same task in a fresh process per version, in
turn (the machine is shared and noisy: the medians and their ratio are what to read). Prints JSON.

    python docs/benchmarks/rollout_overhead_v21/overhead.py OLD_SRC NEW_SRC [--env ID] [--module M] [--repeats 7]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys

CHILD = r"""
import importlib, json, sys, time, numpy as np
if sys.argv[1]:
    importlib.import_module(sys.argv[1])
from shaped_es.policies import MLPSpec
from shaped_es.rollout import make_env, run_task
from shaped_es.rollout.task import RolloutTask
env = make_env(sys.argv[2], {})
spec = MLPSpec(env.observation_space.shape[0], env.action_space.shape[0], (32, 32))
params = (np.random.default_rng(0).standard_normal((16, spec.num_params)) * 0.1).astype(np.float32)  # (16, n)
seeds = np.arange(32).reshape(16, 2)  # (m, E)
out = {}
for record in (False, True, False, True):
    task = RolloutTask(sys.argv[2], {}, spec, params, np.arange(16), seeds, record=record)
    t0 = time.perf_counter()
    res = run_task(task)
    out.setdefault(str(record), []).append((time.perf_counter() - t0) / int(res.lengths.sum()) * 1e6)
print(json.dumps({k: min(v) for k, v in out.items()}))  # us per step; the first of each is a warm-up
"""


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--env", default="cheetah_waypoints:CheetahWaypoints-v0")
    ap.add_argument("--module", default="cheetah_waypoints")
    ap.add_argument("--path", default="docs/benchmarks/backoff_heavy_v13", help="where --module lives")
    ap.add_argument("--repeats", type=int, default=7)
    a = ap.parse_args()
    runs = {"old": [], "new": []}
    for _ in range(a.repeats):
        for name, src in (("old", a.old), ("new", a.new)):
            env = {**os.environ, "PYTHONPATH": os.pathsep.join([src, a.path])}
            res = subprocess.run([sys.executable, "-c", CHILD, a.module, a.env], env=env, capture_output=True,
                                 text=True, check=True)
            runs[name].append(json.loads(res.stdout.strip().splitlines()[-1]))
    med = {n: {k: statistics.median(r[k] for r in rs) for k in ("False", "True")} for n, rs in runs.items()}
    print(json.dumps({"env": a.env, "repeats": a.repeats, "us_per_step_median": {
        n: {"unrecorded": m["False"], "recorded": m["True"]} for n, m in med.items()},
        "new_over_old": {"unrecorded": med["new"]["False"] / med["old"]["False"],
                         "recorded": med["new"]["True"] / med["old"]["True"]},
        "recording_overhead_us": {n: m["True"] - m["False"] for n, m in med.items()}}, indent=1))


if __name__ == "__main__":
    main()
