"""The label probe (``shaped-es check-env ID --labels``, ``guides/label_probe.py``) on every suite task,
6 seeds: M_phi's label-driven return per frame and query clip, zero action on the same episodes, and the
choice a shaped run with ``frame: auto`` makes. Prints JSON (``closed_loop.json`` here).

    PYTHONPATH=src python docs/benchmarks/labels_closed_loop/closed_loop.py > docs/benchmarks/labels_closed_loop/closed_loop.json
"""

import json

import numpy as np

from shaped_es.benchmark.suite import suite_tasks
from shaped_es.guides.label_probe import check_labels

SEEDS = range(6)

out = {}
for task in suite_tasks("waypoints"):
    per = [check_labels(task.env, seed=s) for s in SEEDS]
    names = list(per[0]["returns"])
    out[task.env] = {
        "mean_return": {n: round(float(np.mean([np.mean(p["returns"][n]) for p in per])), 2) for n in names}
        | {"zero_action": round(float(np.mean([np.mean(p["zero_action"]) for p in per])), 2)},
        "chosen": [f'{p["chosen"]["frame"]}' + ("" if p["chosen"]["query_clip"] is None else
                                                 f'+clip{p["chosen"]["query_clip"]:g}') for p in per],
        "labels_beat_zero_action": sum(p["verdict"].startswith("labels drive") for p in per),
        "env_steps": int(np.median([p["env_steps"] for p in per])),
        "seconds": round(float(np.median([p["seconds"] for p in per])), 2),
    }
print(json.dumps({"seeds": list(SEEDS), "episodes_per_variant": 10, "tasks": out}, indent=1))
