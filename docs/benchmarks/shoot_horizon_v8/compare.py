"""The tenth session's table: per task, the default with the shooting rival at its fixed 4-step horizon
(``../suite_bodies_v7``'s "with" arm) against the default whose label probe also tries 8 and 16 steps, 10
seeds (0-9): generations to the threshold (censored mean), seeds solved, late test reward, candidates
accepted. Prints JSON.

    python docs/benchmarks/shoot_horizon_v8/compare.py

Where the runs are: a seed whose probe chose the 4-step horizon and kept or dropped the rival as before
runs the code path of ``../suite_bodies_v7`` (its "with" arm stands for it); the seeds whose probe chose
another horizon or changed its verdict (``gate.txt``) ran again at this code: ``suite/TASK/runs/``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "suite_bodies_v7"))
sys.argv = sys.argv[:1]
import io, contextlib  # noqa: E401,E402

with contextlib.redirect_stdout(io.StringIO()):  # v7's table module prints its own JSON on import
    import compare as v7  # noqa: E402

sc = v7.sc


def runs(task: str) -> list[Path]:
    got = dict(enumerate(v7.runs(task, "with")))  # seeds 0-9 in order
    for p in sorted((HERE / "suite" / task).glob("runs/shaped_s*/metrics.csv")):
        got[int(p.parent.name.split("_s")[-1])] = p
    return [got[s] for s in sorted(got)]


out = {}
for task in v7.TASKS:
    before = v7.summary(v7.runs(task, "with"), task)
    after = v7.summary(runs(task), task)
    van = v7.summary(v7.runs(task, "vanilla"), task)
    cma = v7.summary(v7.runs(task, "cmaes"), task)
    rerun = sorted(int(p.parent.name.split("_s")[-1]) for p in (HERE / "suite" / task).glob("runs/shaped_s*/metrics.csv"))
    out[task] = {"fixed_4": before, "probed_4_8_16": after, "vanilla": van, "cmaes": cma, "rerun_seeds": rerun,
                 "fixed_over_vanilla": round(before["gens"] / van["gens"], 3),
                 "probed_over_vanilla": round(after["gens"] / van["gens"], 3)}
geo = lambda k: float(np.exp(np.mean([np.log(out[t][k]) for t in v7.TASKS])))  # noqa: E731
out["geomean_over_vanilla"] = {"fixed_4": round(geo("fixed_over_vanilla"), 3),
                               "probed_4_8_16": round(geo("probed_over_vanilla"), 3)}
print(json.dumps(out, indent=1))
