"""The mean's and the rivals' clones on threads against one after another: per executor, body and seed, the
new run's wall time and summed ``time_cloning_s`` over the old one's, and whether every metrics row but its
time columns is the same. Reads ``ab/<executor>/<env>/{old,new}_s<seed>/metrics.csv`` next to this file.

    python docs/benchmarks/clone_threads_v13/compare.py > compare.json
"""

import csv
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent


def timeless(row: dict) -> dict:
    return {k: v for k, v in row.items() if not (k.endswith("_s") or "time" in k)}


def main() -> None:
    out = {}
    for env_dir in sorted((HERE / "ab").glob("*/*")):
        ex, env = env_dir.parent.name, env_dir.name
        per = []
        for old in sorted(env_dir.glob("old_s*")):
            new = env_dir / old.name.replace("old", "new")
            a, b = (list(csv.DictReader((d / "metrics.csv").open(newline=""))) for d in (old, new))
            clone = [sum(float(r["time_cloning_s"] or 0) for r in rows) for rows in (a, b)]
            per.append({"seed": int(old.name.split("_s")[1]), "same_rows": list(map(timeless, a)) == list(map(timeless, b)),
                        "wall_old_s": float(a[-1]["wall_time_s"]), "wall_new_over_old": float(b[-1]["wall_time_s"]) / float(a[-1]["wall_time_s"]),
                        "clone_old_s": clone[0], "clone_new_over_old": clone[1] / clone[0]})
        out[f"{ex}/{env}"] = {"per_seed": per, "all_rows_same": all(p["same_rows"] for p in per),
                              "wall_new_over_old_median": float(np.median([p["wall_new_over_old"] for p in per])),
                              "clone_new_over_old_median": float(np.median([p["clone_new_over_old"] for p in per]))}
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
