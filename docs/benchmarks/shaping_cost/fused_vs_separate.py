"""Three runs side by side in one process (issue #28): vanilla, shaped with the extras fused into the
population's worker calls (the default), shaped with the extras as tasks of their own (the old path, via
the guide's rollout_fn); same seeds, so the same work; the order rotates every generation.
``PYTHONPATH=src python docs/benchmarks/shaping_cost/fused_vs_separate.py CarNav-v0 20``"""
import json, statistics, sys, tempfile
from pathlib import Path
from threadpoolctl import threadpool_limits
from shaped_es.config import build_config, merge
from shaped_es.speed.shaping_cost import _Stepper
from shaped_es.rollout import run_task

def main():
    env, timed, warm = sys.argv[1], int(sys.argv[2]), 3
    base = {"env": env, "generations": warm + timed, "executor": "process", "workers": None, "tensorboard": False, "seed": 0}
    cfgs = {"vanilla": build_config({**base, "method": "vanilla"}),
            "fused": build_config(merge({**base, "method": "shaped"}, {"shaping": {"backoff_after": 0}})),
            "separate": build_config(merge({**base, "method": "shaped"}, {"shaping": {"backoff_after": 0}}))}
    with tempfile.TemporaryDirectory() as tmp, threadpool_limits(limits=1):
        from shaped_es.trainer import _limit_torch_threads
        runs = {k: _Stepper(c, Path(tmp) / k) for k, c in cfgs.items()}
        _limit_torch_threads()
        runs["separate"].trainer.guide.rollout_fn = lambda: run_task  # the old path: extras as tasks of their own
        names = list(runs)
        for g in range(warm + timed):
            order = names[g % 3:] + names[:g % 3]
            for k in order:
                runs[k].step(g, timed=g >= warm)
        for r in runs.values(): r.close()
    med = lambda xs: round(1e3 * statistics.median(xs), 1)
    print(json.dumps({"env": env, **{k: {"gen_ms": med(r.wall), "rollout_ms": med([x["rollout_time_s"] for x in r.rows])} for k, r in runs.items()}}))

if __name__ == "__main__":
    main()
