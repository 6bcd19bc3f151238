"""``shaped-es speed`` (alias ``bench``): the speed benchmarks that print figures (``speed/``)."""

from __future__ import annotations

import argparse
import json


def add_speed_parser(sub) -> argparse.ArgumentParser:
    from shaped_es.config import set_item

    # "speed", so it is not confused with "benchmark" (the multi-seed study); "bench" still works
    b = sub.add_parser("speed", aliases=["bench"], help="speed benchmarks that print figures (JSON with --json)")
    bsub = b.add_subparsers(dest="what", required=True)
    be = bsub.add_parser("env", help="env + policy steps per second on all cores",
                         description="Env + policy steps per second on all cores, stepped as training steps "
                                     "the env: through its batched core (env.unwrapped.batch_core) when it "
                                     "has one, else one Gymnasium env instance per copy (the JSON's loop).")
    be.add_argument("env_id", help="Gymnasium id, e.g. CarNav-v0 or mymodule:MyEnv-v0")
    be.add_argument("--num-envs", type=int, default=1024, help="env copies stepped together per worker")
    be.add_argument("--workers", type=int, help="worker processes (default: all cores)")
    be.add_argument("--seconds", type=float, default=6.0, help="how long to measure")
    be.add_argument("--json", action="store_true", help="one line of JSON")
    be.set_defaults(fn=cmd_bench)
    bx = bsub.add_parser("executors", help="generation time and overhead per executor (population 64)")
    bx.add_argument("--executors", default="process,ray,mpi", help="comma-separated (default: all)")
    bx.add_argument("--env", help="env id (default: CarNav-v0)")
    bx.add_argument("--pairs", type=int, default=32, help="antithetic pairs (population = 2 x pairs)")
    bx.add_argument("--workers", type=int, help="worker count (default: all cores)")
    bx.add_argument("--generations", type=int, default=5, help="timed generations (median reported)")
    bx.add_argument("--json", action="store_true", help="one line of JSON")
    bx.set_defaults(fn=cmd_bench_executors)
    from shaped_es.speed import strategy_speed

    bst = bsub.add_parser("strategies", help="ES master per generation (ask + tell + guide) vs policy size")
    strategy_speed.add_arguments(bst)  # --sizes 2.4k,100k,1M --strategies --generations --json ...
    bst.set_defaults(fn=strategy_speed.run_cli)
    bs = bsub.add_parser("shaping", help="a shaped generation vs a vanilla one, side by side, per phase")
    bs.add_argument("--envs", default="CarNav-v0,UR5Reach-v0", help="comma-separated env ids")
    bs.add_argument("--generations", type=int, default=10, help="timed generations (medians reported)")
    bs.add_argument("--warmup", type=int, default=3, help="untimed generations first")
    bs.add_argument("--executor", default="process", choices=("inline", "process"), help="where rollouts run")
    bs.add_argument("--workers", type=int, help="worker processes (default: all cores)")
    bs.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", type=set_item,
                    help="config override for the shaped run only, e.g. shaping.cloning.steps=5")
    bs.add_argument("--json", action="store_true", help="one line of JSON")
    bs.set_defaults(fn=cmd_bench_shaping)
    return b


def cmd_bench(a: argparse.Namespace) -> int:
    import shaped_es  # noqa: F401
    from shaped_es.speed.env_speed import bench_env
    from shaped_es.rollout import make_env

    make_env(a.env_id, {}).close()  # one clear error for unknown ids before spawning workers
    res = bench_env(a.env_id, num_envs=a.num_envs, workers=a.workers, seconds=a.seconds)
    print(json.dumps(res) if a.json else "\n".join(f"{k}: {v}" for k, v in res.items()))
    return 0


def cmd_bench_executors(a: argparse.Namespace) -> int:
    from shaped_es.speed.executor_overhead import bench_executors

    names = [n.strip() for n in a.executors.split(",") if n.strip()]
    res = bench_executors(tuple(names), env_id=a.env, pairs=a.pairs, workers=a.workers,
                          generations=a.generations)
    print(json.dumps(res) if a.json else json.dumps(res, indent=2))
    return 0


def cmd_bench_shaping(a: argparse.Namespace) -> int:
    from shaped_es.speed.shaping_cost import bench_shaping, format_table
    from shaped_es.config import parse_set

    envs = tuple(e.strip() for e in a.envs.split(",") if e.strip())
    res = bench_shaping(envs, generations=a.generations, warmup=a.warmup, executor=a.executor,
                        workers=a.workers, overrides=parse_set(a.set))
    print(json.dumps(res) if a.json else format_table(res))
    return 0
