"""Bodies the method was not developed on (``bodies.py``: the tractor and the hover; ``drone.py`` and
``boat.py``: two new users' own envs, written from the README alone): per arm, 10 seeds (0-9), 40
generations each, generations to the threshold (censored mean: a seed that never reaches it counts 41),
seeds solved, the final test reward's mean, candidates accepted per run. Prints JSON.

    python docs/benchmarks/shoot_horizon_v8/heldout/compare.py

Arms (``runs/BODY/ARM/shaped_sK/metrics.csv`` etc.):
- ``before``: the default before the shooting rival (the eighth session's code), with ``vanilla`` and ``cmaes``;
- ``shoot4``: the shooting rival at its fixed 4-step horizon (the ninth session's code);
- ``probed``: the probe chooses the horizon; a seed whose probe chose the 4-step horizon runs shoot4's code
  path (its run stands for it), the seeds in ``probed/`` ran again;
- ``probed_and_4``: this code, where the 4-step rival also runs beside a longer chosen horizon whose 4-step
  candidate beat zero action too (``probed_and_4/``; the drone's never did: its arm is ``probed``).
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
BODIES = {"Tractor-v0": -6.0, "Hover3D-v0": 8.5, "MyDrone-v0": 8.0, "MyBoat-v0": 8.5}
BUDGET = 40


def one(path: Path, threshold: float) -> dict:
    with path.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    test = [float(r["test_reward_mean"]) for r in rows if r["test_reward_mean"]]
    hit = next((i + 1 for i, x in enumerate(test) if x >= threshold), BUDGET + 1)
    acc = sum(r.get("candidate_accepted") == "1" for r in rows)
    return {"gens": hit, "final": test[-1], "accepted": acc, "wall": float(rows[-1]["wall_time_s"])}


def arm(body: str, name: str) -> dict[int, Path]:
    d = HERE / "runs" / body
    got = {}
    chain = {"probed": ["shoot4", "probed"], "probed_and_4": ["shoot4", "probed", "probed_and_4"]}
    for src in chain.get(name, [name]):
        for p in sorted((d / src).glob("*_s*/metrics.csv")):
            got[int(p.parent.name.split("_s")[-1])] = p
    return got


out = {}
for body, thr in BODIES.items():
    out[body] = {}
    for name in ("before", "shoot4", "probed", "probed_and_4", "oracle", "vanilla", "cmaes"):
        runs = arm(body, name)
        if not runs:
            continue
        per = [one(runs[s], thr) for s in sorted(runs)]
        g = np.array([x["gens"] for x in per])
        out[body][name] = {"seeds": len(per), "solved": int((g <= BUDGET).sum()), "gens": round(float(g.mean()), 1),
                           "gens_per_seed": g.tolist(), "final": round(float(np.mean([x["final"] for x in per])), 2),
                           "accepted_per_run": round(float(np.mean([x["accepted"] for x in per])), 1),
                           "wall_s": round(float(np.mean([x["wall"] for x in per])), 1)}
    for name in ("probed", "probed_and_4"):
        if name in out[body] and "vanilla" in out[body]:
            out[body][f"{name}_over_vanilla"] = round(out[body][name]["gens"] / out[body]["vanilla"]["gens"], 3)
print(json.dumps(out, indent=1))
