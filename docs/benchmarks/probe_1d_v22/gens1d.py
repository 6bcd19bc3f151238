"""The 1-D bodies' runs: generations and wall time to the threshold (censored: an unsolved run counts budget + 1
generations and its whole run's seconds), seeds solved, late test reward (last 10 generations), for the shaped runs
with the probe on a line (``BODY/new``), without it (``BODY/old``, the previous default) and Vanilla-ES
(``BODY/old/vanilla_sK``), with percentile-bootstrap intervals of the ratios of means. Prints JSON.

    python gens1d.py BODY THRESHOLD GENERATIONS     (stdlib + NumPy; e.g. rail 9.5 40)"""
import csv
import json
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def runs(folder: Path, method: str, thr: float, budget: int) -> list[tuple[int, float, float]]:
    out = []
    for d in sorted(folder.glob(f"{method}_s*"), key=lambda p: int(p.name.rsplit("_s", 1)[1])):
        rows = list(csv.DictReader((d / "metrics.csv").open(newline="")))
        t = np.array([float(r["test_reward_mean"]) for r in rows])  # (G,)
        hit = np.flatnonzero(t >= thr)
        wall = float(rows[hit[0]]["wall_time_s"]) if hit.size else float(rows[-1]["wall_time_s"])
        out.append((int(hit[0]) + 1 if hit.size else budget + 1, float(t[-10:].mean()), wall))
    return out


def boot(a, b, n=4000, seed=0) -> list[float]:
    a, b = np.asarray(a, float), np.asarray(b, float)
    i = np.random.default_rng(seed).integers(0, len(a), (n, len(a)))  # (n, seeds) paired resamples
    r = a[i].mean(1) / b[i].mean(1)
    return [round(float(np.percentile(r, 2.5)), 2), round(float(np.percentile(r, 97.5)), 2)]


def main(body: str, thr: str, budget: str) -> dict:
    t, b = float(thr), int(budget)
    arms = {"probe": runs(HERE / body / "new", "shaped", t, b), "no_probe": runs(HERE / body / "old", "shaped", t, b),
            "vanilla": runs(HERE / body / "old", "vanilla", t, b)}
    res = {k: {"seeds": len(v), "gens": round(float(np.mean([g for g, _, _ in v])), 2),
               "solved": sum(g <= b for g, _, _ in v), "late": round(float(np.mean([x for _, x, _ in v])), 3),
               "wall_to_threshold_s": round(float(np.mean([w for _, _, w in v])), 1),
               "per_seed": [g for g, _, _ in v]} for k, v in arms.items() if v}
    for other in ("no_probe", "vanilla"):
        a, o = arms["probe"], arms[other]
        res[f"probe_vs_{other}"] = {
            "gens": round(float(np.mean([g for g, _, _ in a]) / np.mean([g for g, _, _ in o])), 2),
            "gens_ci": boot([g for g, _, _ in a], [g for g, _, _ in o]),
            "wall": round(float(np.mean([w for _, _, w in a]) / np.mean([w for _, _, w in o])), 2),
            "wall_ci": boot([w for _, _, w in a], [w for _, _, w in o])}
    return res


if __name__ == "__main__":
    json.dump(main(*sys.argv[1:]), sys.stdout, indent=1)
