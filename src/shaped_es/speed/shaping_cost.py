"""What shaping costs: a ``vanilla`` and a ``shaped`` run stepped side by side, generation by generation.

Both trainers run in this process with their own executors (default ``process``, all cores) and the
same config otherwise (population 64, default preset). After ``warmup`` untimed generations (pools,
Numba JIT, torch import), each timed generation runs vanilla then shaped (the order alternates every
generation, so drift in the machine's load hits both alike). A generation's wall time covers all a run
does for it: ask, rollouts, tell, shaping, metrics row and checkpoint (``checkpoint_every = 1``); with
``clone_overlap`` the shaped run's next population, started during its clone, is waited for before the
other run steps (its rollouts are timed in the shaped generation, not in the vanilla one beside it).
CPU per generation (``*_cpu_s``): the run's ``cpu_time_s`` added by the step, master and workers.

Reported per env (medians over the timed generations): the whole generation of each method and their
ratio; the shaped run's phases (rollouts, cloning, time waited for M_phi, M_phi's own time in its
thread, the background shard writes, the checkpoint); and the **batched lower bound** of the shaping
work: M_phi's steps and the labels + cloning of the whole population, timed alone on the master on the
run's last generation of data with nothing else running.

The compiled shaping kernels (``shaping/kernels.py``) are compiled or loaded before the clock; their
one-time cost is reported apart (``kernels``: compile with an empty Numba cache, load from it).

``shaped-es speed shaping --json`` prints one JSON line; ``--set shaping.cloning.steps=5`` (and any
other ``--set``) changes the shaped run only, to price other budgets.
"""

from __future__ import annotations

import json
import os
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from shaped_es.config import build_config, merge

PHASES = ("rollout_time_s", "time_cloning_s", "time_mphi_wait_s", "time_mphi_s", "time_store_write_s")
ENVS = ("CarNav-v0", "UR5Reach-v0")


def _med(xs) -> float | None:
    xs = [float(x) for x in xs if x is not None]
    return statistics.median(xs) if xs else None


class _Stepper:
    """One run driven generation by generation, as ``Trainer.run`` would (rows, checkpoints)."""

    def __init__(self, cfg, root: Path):
        from shaped_es.rundir.store import RunStore
        from shaped_es.trainer import Trainer

        self.store = RunStore(root)
        self.store.create(cfg)
        self.trainer = Trainer(cfg, self.store, progress=False)
        self.rows: list[dict] = []  # the metrics rows completed in timed generations
        self.wall: list[float] = []
        self.checkpoint: list[float] = []
        self.cpu: list[float] = []  # CPU seconds a generation, master and workers (the run's cpu_time_s)

    def step(self, g: int, timed: bool) -> None:
        from concurrent.futures import wait

        t0, cpu0 = time.perf_counter(), self.trainer.c.cpu_time_s
        done = self.trainer.step(g)
        for row in done:
            self.store.append_metrics(row)
        t1 = time.perf_counter()
        self.trainer.checkpoint()
        t2 = time.perf_counter()
        nxt = getattr(self.trainer, "_next", None)  # clone_overlap: the next population, rolling out
        if nxt is not None:  # this run's work: waited for here, not timed in the other run's generation
            wait(nxt.futures)
        t3 = time.perf_counter()
        if timed:
            self.wall.append(t3 - t0)
            self.checkpoint.append(t2 - t1)
            self.cpu.append(self.trainer.c.cpu_time_s - cpu0)
            self.rows.extend(done)

    def close(self) -> None:
        self.trainer._drain()
        self.trainer.close()


def _lower_bound(stepper: _Stepper, g: int) -> dict:
    """M_phi's steps and the mechanism's labels + cloning (the population's, or the mean's), alone on
    the master (``g``'s data)."""
    from shaped_es.guides.mechanisms.mean_clone import clone_mean

    guide = stepper.trainer.guide
    if getattr(guide, "placement", None) != "master" or not guide.labels.ready:
        return {"mphi_s": None, "clone_s": None}
    strategy = stepper.trainer.strategy
    if guide.sh.mechanism == "paper":
        X = np.asarray(strategy.ask(), dtype=np.float32)  # (P, n) a population to clone
        clone = lambda: guide.mechanism._clone(g, X, None, n_tasks=1)  # noqa: E731
    else:
        clone = lambda: clone_mean(guide, g, np.asarray(strategy.mean), guide.mean_clone_cfg)  # noqa: E731
    mphi_s = None
    if guide.mphi is not None:
        state = guide.mphi.state_dict(with_training=True)
        t0 = time.perf_counter()
        guide.mphi.train()
        mphi_s = time.perf_counter() - t0
        guide.mphi.load_state_dict(state)
    clone()  # untimed: reads the history memory no longer holds
    t2 = time.perf_counter()
    clone()
    return {"mphi_s": mphi_s, "clone_s": time.perf_counter() - t2}


def bench_env(env_id: str, generations: int = 10, warmup: int = 3, executor: str = "process",
              workers: int | None = None, overrides: dict | None = None) -> dict:
    base = {"env": env_id, "generations": warmup + generations, "executor": executor, "workers": workers,
            "tensorboard": False, "seed": 0}
    cfgs = {"vanilla": build_config({**base, "method": "vanilla"}),
            # an awake shaped generation's price: the back-off (guides/label_budget.py) would mix in sleeping
            # generations that cost what a vanilla one does
            "shaped": build_config(merge({**base, "method": "shaped", "shaping": {"backoff_after": 0}},
                                         overrides or {}))}
    with tempfile.TemporaryDirectory(prefix="shaped-es-bench-") as tmp, threadpool_limits(limits=1):
        from shaped_es.trainer import _limit_torch_threads

        runs = {m: _Stepper(c, Path(tmp) / m) for m, c in cfgs.items()}
        _limit_torch_threads()
        try:
            for g in range(warmup + generations):
                order = list(runs) if g % 2 == 0 else list(runs)[::-1]
                for m in order:
                    runs[m].step(g, timed=g >= warmup)
            bound = _lower_bound(runs["shaped"], warmup + generations - 1)
        finally:
            for r in runs.values():
                r.close()
        shaped_rows = runs["shaped"].rows
        van, sha = _med(runs["vanilla"].wall), _med(runs["shaped"].wall)
        phases = {k: _med(r.get(k) for r in shaped_rows) for k in PHASES}
        phases["checkpoint_s"] = _med(runs["shaped"].checkpoint)
        return {
            "env": env_id, "timed_generations": generations,
            "vanilla_generation_s": van, "shaped_generation_s": sha,
            "ratio": sha / van if van else None,
            "vanilla_rollout_s": _med(r.get("rollout_time_s") for r in runs["vanilla"].rows),
            "vanilla_checkpoint_s": _med(runs["vanilla"].checkpoint),
            "vanilla_cpu_s": _med(runs["vanilla"].cpu), "shaped_cpu_s": _med(runs["shaped"].cpu),
            "shaped_phases_s": phases,
            "lower_bound_s": {"mphi": bound["mphi_s"], "label_and_clone": bound["clone_s"]},
            "shaping": cfgs["shaped"].shaping.model_dump(mode="json", include={"placement", "history"})
            | {"mphi_steps": cfgs["shaped"].shaping.inverse_dynamics.steps_per_generation,
               "clone_steps": cfgs["shaped"].shaping.cloning.steps,
               "clone_batch": cfgs["shaped"].shaping.cloning.batch_size},
        }


def bench_shaping(envs=ENVS, generations: int = 10, warmup: int = 3, executor: str = "process",
                  workers: int | None = None, overrides: dict | None = None) -> dict:
    for e in envs:  # a bad --set fails here, in one line, before anything runs
        build_config(merge({"env": e, "method": "shaped"}, overrides or {}))
    load0 = _load()
    if load0 is not None and load0 > 0.5 * (os.cpu_count() or 1):
        print(f"shaped-es: warning: the machine is busy (load average {load0:.1f} on {os.cpu_count()} cores): "
              f"the ratio is side by side, but the absolute times will be inflated", file=sys.stderr)
    kern = _kernels_compile()
    res = [bench_env(e, generations, warmup, executor, workers, overrides) for e in envs]
    return {"machine": {"cpus": os.cpu_count(), "python": platform.python_version(),
                        "load_average_1min": {"before": load0, "after": _load()}},
            "executor": executor, "workers": workers or os.cpu_count(), "kernels": kern, "envs": res}


def _kernels_compile() -> dict:
    """The compiled shaping kernels' one-time cost, outside the timed generations (the shaped guide
    loads them before the clock starts): ``compile_s``, a fresh process compiling them with an empty
    Numba cache (once per install; Numba's own start-up included), and ``load_s``, loading them from
    the cache in this process."""
    import subprocess

    from shaped_es.shaping import kernels

    if not kernels.ENABLED:
        return {"enabled": False}
    with tempfile.TemporaryDirectory(prefix="shaped-es-numba-") as cache:
        code = "from shaped_es.shaping import kernels; print(kernels.warm_up())"
        env = {**os.environ, "NUMBA_CACHE_DIR": cache,
               "PYTHONPATH": os.pathsep.join(p for p in (str(Path(__file__).resolve().parents[2]),
                                                         os.environ.get("PYTHONPATH")) if p)}
        try:
            out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                                 timeout=600, check=True).stdout
            compile_s = float(out.strip().splitlines()[-1])
        except (subprocess.SubprocessError, ValueError, IndexError):
            compile_s = None
    return {"enabled": True, "compile_s": compile_s, "load_s": kernels.warm_up()}


def _load() -> float | None:
    """The 1-minute load average (None where the OS has none)."""
    try:
        return round(os.getloadavg()[0], 2)
    except (AttributeError, OSError):
        return None


def format_table(res: dict) -> str:
    lines = [f"{'env':14s} {'vanilla':>9s} {'shaped':>9s} {'ratio':>6s}  shaped phases (median s)"]
    for e in res["envs"]:
        ph = " ".join(f"{k.replace('time_', '').replace('_s', '')}={v:.3f}" for k, v in
                      e["shaped_phases_s"].items() if v is not None)
        lb = e["lower_bound_s"]
        lbs = "" if lb["mphi"] is None else f"  lower bound: mphi={lb['mphi']:.3f} clone={lb['label_and_clone']:.3f}"
        lines.append(f"{e['env']:14s} {e['vanilla_generation_s']:9.3f} {e['shaped_generation_s']:9.3f} "
                     f"{e['ratio']:6.2f}  {ph}{lbs}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> None:
    res = bench_shaping()
    print(json.dumps(res))


if __name__ == "__main__":
    main()
