"""CPU milliseconds (the master and every process under it, from /proc) per timed generation, vanilla then shaped,
as ``speed shaping`` runs them (less sensitive to other sessions' load than wall time; Linux only).
``PYTHONPATH=src python docs/benchmarks/shaping_cost/cpu_per_generation.py CarNav-v0``"""
import json, os, sys, tempfile, time
from pathlib import Path
from threadpoolctl import threadpool_limits
from shaped_es.config import build_config, merge
from shaped_es.speed.shaping_cost import _Stepper

TCK = os.sysconf("SC_CLK_TCK")

def tree_cpu(root: int) -> float:
    kids, stats = {}, {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            f = open(f"/proc/{d}/stat").read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        kids.setdefault(int(f[1]), []).append(int(d)); stats[int(d)] = (int(f[11]) + int(f[12])) / TCK
    tot, todo = 0.0, [root]
    while todo:
        p = todo.pop(); tot += stats.get(p, 0.0); todo += kids.get(p, [])
    return tot

def main():
    env = sys.argv[1]; warm, timed = 3, 10
    out = {}
    for method in ("vanilla", "shaped"):
        base = {"env": env, "generations": warm + timed, "executor": "process", "workers": None,
                "tensorboard": False, "seed": 0, "method": method}
        cfg = build_config(merge(base, {"shaping": {"backoff_after": 0}}) if method == "shaped" else base)
        with tempfile.TemporaryDirectory() as tmp, threadpool_limits(limits=1):
            from shaped_es.trainer import _limit_torch_threads
            st = _Stepper(cfg, Path(tmp) / method); _limit_torch_threads()
            for g in range(warm + timed):
                if g == warm:
                    c0, w0 = tree_cpu(os.getpid()), time.perf_counter()
                st.step(g, timed=g >= warm)
            st.trainer._drain()
            out[method] = {"cpu_per_gen_ms": 1e3 * (tree_cpu(os.getpid()) - c0) / timed,
                           "wall_per_gen_ms": 1e3 * (time.perf_counter() - w0) / timed}
            st.close()
    print(json.dumps({"env": env, **out}))

if __name__ == "__main__":
    main()
