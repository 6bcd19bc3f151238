"""The README's suite table at this session's default: per task, the shaped runs (``suite_rp3`` where it ran a
task, else the default's committed runs: a run that undid nothing at margin 2 is the same at 3) beside Vanilla-ES's
and CMA-ES's runs of ``../test_policy_v11/suite``: generations to the threshold (censored means), seeds solved,
shaped / Vanilla-ES and shaped / CMA-ES with 95% bootstrap intervals, late test reward, and the geometric mean
of the shaped / Vanilla-ES ratios. Prints JSON.   PYTHONPATH=src python table.py"""
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from suite_compare import OLD, SUITES, boot, run, threshold_of  # noqa: E402

V11 = HERE.parent / "test_policy_v11" / "suite"
out = {}
for task in SUITES["waypoints"]:
    thr, G = threshold_of(task.env)[0], task.generations

    def arm(method: str, dirs) -> list[dict]:
        rows = []
        for s in range(10):
            got = None
            for d in dirs:
                r = run(d / task.env / "runs" / f"{method}_s{s}", thr, G)
                got = r or got
            rows.append(got)
        return rows

    shaped = arm("shaped", OLD + [HERE / "suite_rp3"])  # the newest run of each seed
    van, cma = arm("vanilla", [V11]), arm("cmaes", [V11])
    g = {k: [r["g"] for r in v] for k, v in (("shaped", shaped), ("vanilla", van), ("cmaes", cma))}
    out[task.env] = {**{k: round(float(np.mean(v)), 2) for k, v in g.items()},
                     **{f"{k}_solved": sum(x <= G for x in v) for k, v in g.items()},
                     "vs_vanilla": round(float(np.mean(g["shaped"]) / np.mean(g["vanilla"])), 2),
                     "vs_vanilla_ci": boot(g["shaped"], g["vanilla"]),
                     "vs_cmaes": round(float(np.mean(g["shaped"]) / np.mean(g["cmaes"])), 2),
                     "vs_cmaes_ci": boot(g["shaped"], g["cmaes"]),
                     "late": [round(float(np.mean([r["late"] for r in v])), 3) for v in (shaped, van, cma)]}
out["geomean_vs_vanilla"] = round(float(np.exp(np.mean([np.log(v["vs_vanilla"]) for v in out.values()]))), 3)
json.dump(out, sys.stdout, indent=1)
