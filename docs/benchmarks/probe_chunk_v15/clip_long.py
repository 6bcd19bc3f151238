"""``probe_clip_long=4`` (off): the label probe also offers every variant with the query clipped to 4 mean steps.
The runs in ``clip_long/`` were made with the option on, before its last rule (a clip-4 variant stands only
where the labels chosen without it do not drive the body better); this applies the final rule to each run's
``label_probe.json``: where clip 4 stands, the run is the one kept; where the rule sets it aside, the final code
chooses as without the option (every other simulated candidate keeps its seed stream, and generation 0's
candidate is chosen without the clip-4 clones), so the run is the default's (``suite/``, ``diffbot/default``,
``../heldout_bicycle_v15/bench``). Per body: generations to the threshold, the option against the default. The robot's seeds 10-19
and the Reacher's (``clip_long/reacher_10_19``, both arms) were run at the final code.

    python docs/benchmarks/probe_chunk_v15/clip_long.py > clip_long.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from compare import metrics, to_threshold  # this folder's compare.py
from shaped_es.benchmark.summary import threshold_of
from shaped_es.guides import probe_candidate
from shaped_es.guides.probe_choice import choose_targets

HERE = Path(__file__).resolve().parent


def final_choice(d: dict) -> str:
    """The variant the final rule chooses from a probe file's returns (the ranking as the probe builds it)."""
    returns = {k: np.array(v) for k, v in d["returns"].items()}
    clones = {k: np.array(v) for k, v in d["clones"].items()}
    sims = {**d["clones"], **{f"shoot:{h}": v for h, v in (d.get("shoot_tried") or {}).items()}}
    if not d.get("shoot_tried") and d.get("shoot"):  # one horizon probed: the file keeps it as shoot
        sims[f"shoot:{d.get('shoot_horizon')}"] = d["shoot"]
    ranking = probe_candidate.rank(sims, dict.fromkeys(sims))  # as the probe ranks them
    return choose_targets(returns, "both", np.array(d["zero_action"]), clones, ranking, "+clip4")[0]


def body(runs: Path, base: Path, thr: float) -> dict:
    seeds, option, default, kept = [], [], [], []
    for r in sorted(runs.glob("shaped_s*"), key=lambda p: int(p.name[8:])):
        keep = "+clip4" in final_choice(json.loads((r / "label_probe.json").read_text()))
        g_base = to_threshold(metrics(base / r.name), thr)
        seeds.append(int(r.name[8:]))
        option.append(to_threshold(metrics(r), thr) if keep else g_base)
        default.append(g_base)
        kept.append(keep)
    return {"seeds": seeds, "threshold": thr, "option": option, "default": default, "clip4_kept": kept,
            "mean": {"option": float(np.mean(option)), "default": float(np.mean(default))}}


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    out = {"diffbot": body(HERE / "clip_long/diffbot/runs", HERE / "diffbot/default/runs", 8.5),
           "bicycle": body(HERE / "clip_long/bicycle/runs", HERE.parent / "heldout_bicycle_v15/bench/runs", 8.4)}
    for task in sorted((HERE / "clip_long/suite").iterdir()):
        out[task.name] = body(task / "runs", HERE / "suite" / task.name / "runs", threshold_of(task.name)[0])
    out["ReacherWay-v0, seeds 10-19"] = body(HERE / "clip_long/reacher_10_19/option",  # both arms at the final code
                                             HERE / "clip_long/reacher_10_19/default", threshold_of("ReacherWay-v0")[0])
    json.dump(out, sys.stdout, indent=1)
    print()
