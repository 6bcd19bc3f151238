"""The suite's shaped runs at one code version (this folder's ``suite/``) beside the README table's shaped runs,
which were assembled from the newest run of each seed over six studies at six code versions (the latest of
../probe_clip_long_v16/suite, ../shoot_keep_best_v17/KB, ../shoot_unjudged_v18/suite, ../shoot_unjudged_all_v19/suite,
../probe_horizon32_v20/suite, ../revert_paired_v22/suite_rp3), and the baselines of ../test_policy_v11/suite.

Per task: generations to the threshold (censored means: an unsolved seed counts as budget + 1), seeds solved,
shaped / Vanilla-ES and shaped / CMA-ES with 95% bootstrap intervals of the ratio of means, the late test reward
(the last 10 generations), candidates accepted; per seed whether the run equals the table's row for row (every
metrics column but the clocks) and, where not, both generations. Prints JSON.

    PYTHONPATH=src python docs/benchmarks/suite_one_version_v24/compare.py [SUITE_DIR]"""
import csv
import json
import sys
from pathlib import Path

import numpy as np

from shaped_es.benchmark.suite import SUITES
from shaped_es.envs.thresholds import threshold_of

HERE = Path(__file__).resolve().parent
B = HERE.parent
TABLE = [B / "probe_clip_long_v16/suite", B / "shoot_keep_best_v17/KB", B / "shoot_unjudged_v18/suite",
         B / "shoot_unjudged_all_v19/suite", B / "probe_horizon32_v20/suite", B / "revert_paired_v22/suite_rp3"]
BASE = B / "test_policy_v11/suite"
CLOCKS = {"wall_time_s", "cpu_time_s", "gen_time_s", "rollout_time_s", "time_mphi_s", "time_mphi_wait_s",
          "time_cloning_s", "clone_cpu_time_s", "time_store_write_s", "startup_time_s", "time_probe_s"}


def rows(d: Path, budget: int):
    f = d / "metrics.csv"
    if not f.exists():
        return None
    r = list(csv.DictReader(open(f)))
    return r if len(r) >= budget else None


def summary(r, thr: float, budget: int) -> dict:
    t = np.array([float(x["test_reward_mean"]) for x in r[:budget]])
    hit = np.flatnonzero(t >= thr)
    return dict(g=int(hit[0]) + 1 if hit.size else budget + 1, late=float(t[-10:].mean()),
                acc=sum(x.get("candidate_accepted") == "1" for x in r[:budget]))


def same(a, b, budget: int) -> bool:
    """Row for row equal over the budget, every column both have but the clocks."""
    keys = [k for k in a[0] if k in b[0] and k not in CLOCKS and not k.endswith("_time_s")]
    return all(x[k] == y[k] for x, y in zip(a[:budget], b[:budget]) for k in keys)


def boot(a, b, n=4000, rng=np.random.default_rng(0)):
    a, b = np.asarray(a, float), np.asarray(b, float)
    i = rng.integers(0, len(a), (n, len(a)))
    r = a[i].mean(1) / b[i].mean(1)
    return [round(float(np.percentile(r, 2.5)), 2), round(float(np.percentile(r, 97.5)), 2)]


def main(new: Path) -> dict:
    out = {}
    for task in SUITES["waypoints"]:
        thr, G = threshold_of(task.env)[0], task.generations
        got = {"shaped": [], "table": [], "vanilla": [], "cmaes": []}
        seeds = []
        for s in range(10):
            n = rows(new / task.env / "runs" / f"shaped_s{s}", G)
            old = None
            for d in TABLE:
                old = rows(d / task.env / "runs" / f"shaped_s{s}", G) or old
            v, c = (rows(BASE / task.env / "runs" / f"{m}_s{s}", G) for m in ("vanilla", "cmaes"))
            if n is None or old is None or v is None or c is None:
                continue
            for k, r in (("shaped", n), ("table", old), ("vanilla", v), ("cmaes", c)):
                got[k].append(summary(r, thr, G))
            seeds.append((s, same(n, old, G), got["shaped"][-1]["g"], got["table"][-1]["g"]))
        if not seeds:
            continue
        g = {k: [x["g"] for x in v] for k, v in got.items()}
        out[task.env] = {
            "seeds": len(seeds),
            **{k: round(float(np.mean(v)), 2) for k, v in g.items()},
            **{f"{k}_solved": sum(x <= G for x in v) for k, v in g.items()},
            "vs_vanilla": round(float(np.mean(g["shaped"]) / np.mean(g["vanilla"])), 2),
            "vs_vanilla_ci": boot(g["shaped"], g["vanilla"]),
            "vs_cmaes": round(float(np.mean(g["shaped"]) / np.mean(g["cmaes"])), 2),
            "vs_cmaes_ci": boot(g["shaped"], g["cmaes"]),
            "late": {k: round(float(np.mean([x["late"] for x in v])), 3) for k, v in got.items()},
            "accepted": sum(x["acc"] for x in got["shaped"]),
            "same_as_table": sum(x[1] for x in seeds),
            "differ": [(s, gn, go) for s, eq, gn, go in seeds if not eq],
        }
    done = [v for v in out.values() if v["seeds"] == 10]
    if done:
        out["geomean_vs_vanilla"] = round(float(np.exp(np.mean([np.log(v["vs_vanilla"]) for v in done]))), 3)
    return out


if __name__ == "__main__":
    json.dump(main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE / "suite"), sys.stdout, indent=1)
