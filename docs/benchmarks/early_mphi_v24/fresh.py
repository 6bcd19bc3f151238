"""Fresh seeds 10-19: ``shaping.early_mphi=true`` against the default, both run at this session's code, on the tasks
where the suite's seeds 0-9 moved most (UR5Reach-v0, Unicycle-v0, ReacherWay-v0). Prints JSON: per task the
censored mean generations, seeds solved, the ratio with a 95% bootstrap interval, late reward, per seed.

    PYTHONPATH=src python docs/benchmarks/early_mphi_v24/fresh.py EARLY_DIR DEFAULT_DIR [TASK...]"""
import json
import sys
from pathlib import Path

from compare import paired, run
from shaped_es.benchmark.suite import SUITES
from shaped_es.envs.thresholds import threshold_of


def main(early: Path, default: Path, tasks: list[str]) -> dict:
    out = {}
    for task in SUITES["waypoints"]:
        if tasks and task.env not in tasks:
            continue
        thr, G = threshold_of(task.env)[0], task.generations
        pairs = [(s, run(early / task.env / "runs" / f"shaped_s{s}", thr, G),
                  run(default / task.env / "runs" / f"shaped_s{s}", thr, G)) for s in range(10, 20)]
        pairs = [(s, n, o) for s, n, o in pairs if n and o]
        if not pairs:
            continue
        out[task.env] = paired(pairs, G)
    return out


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    json.dump(main(Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3:]), sys.stdout, indent=1)
