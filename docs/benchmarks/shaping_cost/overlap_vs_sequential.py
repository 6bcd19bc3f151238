"""Three runs side by side in one process (issue #28, clone_overlap): vanilla, shaped with the next
population rolling out during the mean's clone (``clone_overlap``, the default) and shaped sequentially
(``clone_overlap=false``, the loop before); same seeds, so the same work and the same numbers; the order
rotates every generation; each shaped run's early population is waited for inside its own timed step
(``speed.shaping_cost._Stepper``). Wall time and CPU (master + workers) per generation, medians.
``PYTHONPATH=src python docs/benchmarks/shaping_cost/overlap_vs_sequential.py CarNav-v0 20 [babble]``"""
import json, os, statistics, sys, tempfile
from pathlib import Path
from threadpoolctl import threadpool_limits
from shaped_es.config import build_config, merge
from shaped_es.speed.shaping_cost import _Stepper


def main():
    env, timed, warm = sys.argv[1], int(sys.argv[2]), 3
    babble = int(sys.argv[3]) if len(sys.argv) > 3 else 16
    base = {"env": env, "generations": warm + timed, "executor": "process", "workers": None, "tensorboard": False,
            "seed": 0}
    shaped = merge({**base, "method": "shaped"}, {"shaping": {"backoff_after": 0, "inverse_dynamics": {"babble": babble}}})
    cfgs = {"vanilla": build_config({**base, "method": "vanilla"}),
            "overlap": build_config(shaped),
            "sequential": build_config({**shaped, "clone_overlap": False})}
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp, threadpool_limits(limits=1):
        from shaped_es.trainer import _limit_torch_threads
        runs = {k: _Stepper(c, Path(tmp) / k) for k, c in cfgs.items()}
        _limit_torch_threads()
        names = list(runs)
        for g in range(warm + timed):
            order = names[g % 3:] + names[:g % 3]
            for k in order:
                runs[k].step(g, timed=g >= warm)
        overlapped = runs["overlap"].trainer.overlapped
        for r in runs.values():
            r.close()
    med = lambda xs: round(1e3 * statistics.median(xs), 1)
    out = {"env": env, "babble": babble, "timed": timed, "load": [round(load0, 2), round(os.getloadavg()[0], 2)],
           "overlapped_generations": overlapped}
    for k, r in runs.items():
        out[k] = {"gen_ms": med(r.wall), "cpu_ms": med(r.cpu),
                  "rollout_ms": med([x["rollout_time_s"] for x in r.rows])}
        if k != "vanilla":
            out[k]["clone_ms"] = med([x["time_cloning_s"] for x in r.rows])
            out[k]["ratio"] = round(statistics.median(r.wall) / statistics.median(runs["vanilla"].wall), 2)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
