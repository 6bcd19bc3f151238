"""The tested policy's rule (``rollout.test_policy``): the population's best member (``best``, the paper's
rule) against the search's mean (``mean``, the centre of each generation's population), for the shaped
method, Vanilla-ES and CMA-ES on every suite task (seeds 0-9; UR5Reach-v0, the Reacher and the kart also
10-19) and on the four held-out bodies.

The runs under ``mean`` train exactly as the committed runs under ``best`` (the same ``train_reward_mean``
in every row; this script checks it), so the two rules are compared on the same training runs: only the
policy that is tested differs. Per task and method: generations to the threshold (censored mean: an
unsolved seed counts as the budget + 1), seeds solved, late test reward (the last 10 generations' mean) and,
per method, the paired difference of late reward (mean - best) with a 95% bootstrap interval; the shaped
method's ratio of mean generations to Vanilla-ES's and CMA-ES's under each rule, with 95% bootstrap
intervals (seeds resampled in pairs). Prints JSON.

    python docs/benchmarks/test_policy_v11/compare.py > docs/benchmarks/test_policy_v11/compare.json
"""

from __future__ import annotations

import contextlib
import csv
import importlib.util
import io
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TASKS = {"PointVel-v0": (8.5, 80), "PointForce-v0": (8.5, 80), "Unicycle-v0": (8.5, 50), "Rover-v0": (8.0, 80),
         "Kart-v0": (8.0, 120), "ReacherWay-v0": (-6.5, 80), "SwimmerWay-v0": (30.0, 30),
         "CarNav-v0": (200.0, 80), "UR5Reach-v0": (40.0, 60)}
TWENTY = ("UR5Reach-v0", "ReacherWay-v0", "Kart-v0")
HELDOUT = {"hover": "Hover3D-v0", "tractor": "Tractor-v0", "drone": "MyDrone-v0", "boat": "MyBoat-v0"}
METHODS = ("shaped", "vanilla", "cmaes")


def _load(name: str, path: Path):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    argv, sys.argv = sys.argv, sys.argv[:1]
    with contextlib.redirect_stdout(io.StringIO()):  # that module prints its own JSON when loaded
        spec.loader.exec_module(mod)
    sys.argv = argv
    return mod


ahead = _load("compare_ahead", HERE.parent / "shoot_ahead_v10" / "compare.py")


def best_path(task: str, seed: int, method: str) -> Path:
    """The committed run under the ``best`` rule (the default's code: accept_flat's CarNav-v0 runs)."""
    if task == "CarNav-v0" and method == "shaped":
        return HERE.parent / "accept_flat_v10" / "suite" / task / "runs" / f"shaped_s{seed}" / "metrics.csv"
    return ahead.path(task, seed, "ahead_1" if method == "shaped" else method)


def mean_path(task: str, seed: int, method: str) -> Path:
    return HERE / ("suite" if seed < 10 else "suite_10_19") / task / "runs" / f"{method}_s{seed}" / "metrics.csv"


def _rows(path: Path) -> list[dict]:
    with path.open(newline="") as fh:
        return list(csv.DictReader(fh))


def one(rows: list[dict], threshold: float, budget: int) -> tuple[int, float]:
    t = [float(r["test_reward_mean"]) for r in rows]
    return next((i + 1 for i, x in enumerate(t) if x >= threshold), budget + 1), float(np.mean(t[-10:]))


def boot_mean(x: np.ndarray, rng) -> list[float]:
    b = x[rng.integers(0, x.size, (10_000, x.size))].mean(axis=1)  # (B,)
    return [round(float(v), 2) for v in np.percentile(b, [2.5, 97.5])]


def ratio(a: np.ndarray, b: np.ndarray, rng) -> list[float]:
    """Ratio of mean generations a / b with a 95% bootstrap interval (seeds resampled in pairs)."""
    i = rng.integers(0, a.size, (10_000, a.size))  # (B, S)
    r = a[i].mean(axis=1) / b[i].mean(axis=1)
    return [round(float(a.mean() / b.mean()), 2)] + [round(float(v), 2) for v in np.percentile(r, [2.5, 97.5])]


def compare(paths: dict, threshold: float, budget: int, rng) -> dict | None:
    """``paths[(method, rule)]``: the runs' metrics.csv per seed. None unless every run under ``mean`` is
    there; a method whose ``best`` runs are not all there (the kart's CMA-ES on seeds 10-19) has ``mean`` only.
    ``same_training``: every run under ``mean`` has the ``train_reward_mean`` column of its run under ``best``
    (the older Vanilla-ES and CMA-ES runs of seeds 10-19 do not: they ran at an older code)."""
    if not all(p.exists() for m in METHODS for p in paths[(m, "mean")]):
        return None
    res, gens = {}, {}
    for method in METHODS:
        runs = {"mean": [_rows(p) for p in paths[(method, "mean")]]}
        if all(p.exists() for p in paths[(method, "best")]):
            runs["best"] = [_rows(p) for p in paths[(method, "best")]]
        res[method], late = {}, {}
        for rule, rr in runs.items():
            g, lt = map(np.array, zip(*(one(r, threshold, budget) for r in rr)))
            gens[(method, rule)], late[rule] = g.astype(float), lt
            res[method][f"_late_{rule}"] = lt.tolist()
            res[method][rule] = {"gens": round(float(g.mean()), 1), "solved": int((g <= budget).sum()),
                                 "late": round(float(lt.mean()), 2), "late_ci": boot_mean(lt, rng),
                                 "gens_per_seed": g.tolist()}
        if "best" in runs:
            res[method]["same_training"] = all([r["train_reward_mean"] for r in a] == [r["train_reward_mean"] for r in b]
                                               for a, b in zip(runs["best"], runs["mean"]))
            d = late["mean"] - late["best"]
            res[method]["late_mean_minus_best"] = [round(float(d.mean()), 2)] + boot_mean(d, rng)
    for rule in ("best", "mean"):
        for b in ("vanilla", "cmaes"):
            if ("shaped", rule) in gens and (b, rule) in gens:
                res.setdefault("shaped_over", {})[f"{b}_{rule}"] = ratio(gens[("shaped", rule)], gens[(b, rule)], rng)
    for rule in ("best", "mean"):  # the shaped method's late reward minus Vanilla-ES's, seeds in pairs
        if ("shaped", rule) in gens and ("vanilla", rule) in gens:
            d = np.array(res["shaped"][f"_late_{rule}"]) - np.array(res["vanilla"][f"_late_{rule}"])
            res.setdefault("late_shaped_minus_vanilla", {})[rule] = [round(float(d.mean()), 2)] + boot_mean(d, rng)
    for method in METHODS:
        for rule in ("best", "mean"):
            res[method].pop(f"_late_{rule}", None)
    return res


rng = np.random.default_rng(0)
out: dict = {}
for task, (thr, budget) in TASKS.items():
    seeds = range(20) if task in TWENTY else range(10)
    out[task] = {"seeds_0_9": compare({(m, r): [(best_path if r == "best" else mean_path)(task, s, m) for s in range(10)]
                                       for m in METHODS for r in ("best", "mean")}, thr, budget, rng)}
    if task in TWENTY:
        out[task]["seeds_0_19"] = compare({(m, r): [(best_path if r == "best" else mean_path)(task, s, m) for s in seeds]
                                           for m in METHODS for r in ("best", "mean")}, thr, budget, rng)
for rule in ("best", "mean"):
    r = [out[t]["seeds_0_9"]["shaped_over"][f"vanilla_{rule}"][0] for t in TASKS if out[t]["seeds_0_9"]]
    out.setdefault("geomean_shaped_over_vanilla", {})[rule] = round(float(np.exp(np.mean(np.log(r)))), 3) if r else None
ho = ahead.ho9
for body, env in HELDOUT.items():
    runs = HERE / "heldout" / body / "runs"
    paths = {}
    for m in METHODS:
        best = [ho.path(env, m, s) for s in range(10)] if m != "shaped" else \
            [ahead.HERE / "heldout" / "runs" / env / "ahead_1" / f"shaped_s{s}" / "metrics.csv" for s in range(10)]
        paths[(m, "best")], paths[(m, "mean")] = best, [runs / f"{m}_s{s}" / "metrics.csv" for s in range(10)]
    out.setdefault("heldout", {})[body] = compare(paths, ho.BODIES[env], ho.BUDGET, rng)
print(json.dumps(out, indent=1))
