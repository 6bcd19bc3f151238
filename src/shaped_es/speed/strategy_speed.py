"""Strategy speed: the ES master's own work per generation, by strategy and number of parameters.

One generation here is what the master computes between rollouts: ``ask`` (the population), ``tell``
(the mean update from the fitness) and, for Guided ES, ``guide`` (the surrogate subspace of the next
generation from ``k`` surrogate gradients, ``(k, n)`` float64 as the trainer passes them). Fitness is
random (the rollouts are not timed) and the surrogates are one fixed random ``(k, n)`` matrix (the cost
of ``guide`` does not depend on their values). Every figure is the median over ``generations`` timed
generations after ``warmup`` untimed ones, in milliseconds, under ``threadpool_limits(1)`` (one BLAS
thread, as a worker-sharing master has).

Strategies: ``vanilla`` (antithetic ES), ``guided`` (Guided ES, ``k`` = 64 surrogates) and ``cmaes``
(pycma, separable/diagonal above 2000 parameters, as the trainer builds it). pycma keeps several
``(popsize, n)`` float64 arrays; its peak memory is estimated before building it and a size whose
estimate exceeds ``max_cmaes_gb`` (4 GB) is skipped and reported under ``skipped``.

``shaped-es bench strategies [--sizes 2.4k,100k,1M] [--json]``, or
``python -m shaped_es.speed.strategy_speed``.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time

DEFAULT_SIZES = (2400, 100_000, 1_000_000)
STRATEGY_NAMES = ("vanilla", "guided", "cmaes")
# peak bytes per (parameter x population member) of a generation of the diagonal CMA-ES baseline (pycma
# 4.x behind shaped_es's CMAES, the asked population included), measured with tracemalloc at population
# 64 and n = 20k and 100k: 73.5 B (so 1M needs ~4.7 GB)
CMAES_BYTES_PER_PARAM_MEMBER = 74
PHASES = ("ask", "tell", "guide")


def parse_size(text: str) -> int:
    """``"2400"``, ``"2.4k"``, ``"100k"``, ``"1M"`` -> number of parameters (a positive integer)."""
    s = str(text).strip().lower().replace("_", "")
    mult = {"k": 1_000, "m": 1_000_000}.get(s[-1:], 1)
    num = s[:-1] if mult > 1 else s
    try:
        value = float(num) * mult
    except ValueError:
        raise argparse.ArgumentTypeError(f"bad size {text!r} (use e.g. 2400, 2.4k, 100k, 1M)") from None
    if not value >= 1 or value != int(value):
        raise argparse.ArgumentTypeError(f"size must be a positive whole number of parameters, got {text!r}")
    return int(value)


def parse_sizes(text: str) -> tuple[int, ...]:
    """Comma-separated sizes (see :func:`parse_size`)."""
    sizes = tuple(parse_size(t) for t in str(text).split(",") if t.strip())
    if not sizes:
        raise argparse.ArgumentTypeError("no sizes given")
    return sizes


def _count(minimum: int):
    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"must be >= {minimum}, got {value}")
        return value

    return parse


def parse_strategies(text: str) -> tuple[str, ...]:
    names = tuple(t.strip() for t in str(text).split(",") if t.strip())
    bad = [n for n in names if n not in STRATEGY_NAMES]
    if bad or not names:
        raise argparse.ArgumentTypeError(f"unknown strategies {bad}; choose from {list(STRATEGY_NAMES)}")
    return names


def cmaes_bytes(n: int, popsize: int) -> int:
    """Estimated peak memory of the diagonal CMA-ES baseline at ``n`` parameters (bytes)."""
    return int(CMAES_BYTES_PER_PARAM_MEMBER * n * popsize)


def _build(name: str, n: int, pairs: int, seed: int):
    import numpy as np

    from shaped_es.strategies import make_strategy

    x0 = np.random.default_rng([seed, n]).standard_normal(n) * 0.1  # (n,)
    if name == "cmaes":  # as trainer.build_strategy: diagonal above 2000 parameters
        return make_strategy("cmaes", x0, sigma=0.1, pairs=pairs, seed=seed, weight_decay=0.05, mu=25,
                             diagonal_above=2000)
    common = dict(sigma=0.02, lr=0.01, pairs=pairs, seed=seed, fitness_shaping="rank", optimizer="adam")
    if name == "vanilla":
        return make_strategy("vanilla", x0, **common)
    return make_strategy("guided", x0, alpha=0.6, **common)


def time_strategy(name: str, n: int, generations: int = 5, warmup: int = 1, pairs: int = 32,
                  k: int = 64, seed: int = 0) -> dict:
    """Median ms per phase and per generation of one strategy at ``n`` parameters (see module doc)."""
    import numpy as np

    es = _build(name, n, pairs, seed)
    rng = np.random.default_rng([seed, n, 1])
    G = rng.standard_normal((k, n)) if name == "guided" else None  # (k, n) float64 surrogates
    times: dict[str, list[float]] = {p: [] for p in (*PHASES, "generation")}
    for g in range(warmup + generations):
        fitness = rng.standard_normal(es.popsize)  # (2P,) stands in for the rollouts' returns
        t0 = time.perf_counter()
        X = es.ask()  # (2P, n)
        t1 = time.perf_counter()
        es.tell(fitness)
        t2 = time.perf_counter()
        if G is not None:
            es.guide(G)
        t3 = time.perf_counter()
        dtype = str(X.dtype)
        del X
        if g >= warmup:
            for p, dt in zip((*PHASES, "generation"), (t1 - t0, t2 - t1, t3 - t2, t3 - t0)):
                times[p].append(1000.0 * dt)
    out = {"strategy": name, "n": n, "popsize": es.popsize, "k": k if G is not None else 0,
           "population_dtype": dtype}
    out |= {f"{p}_ms": round(statistics.median(v), 3) for p, v in times.items() if name == "guided"
            or p != "guide"}
    out["gen_ms"] = out.pop("generation_ms")
    return out


def bench_strategies(sizes=DEFAULT_SIZES, strategies=STRATEGY_NAMES, generations: int = 5,
                     warmup: int = 1, pairs: int = 32, k: int = 64, max_cmaes_gb: float = 4.0,
                     seed: int = 0) -> dict:
    """Time every (strategy, size) under one BLAS thread; one JSON-able dict (see module doc)."""
    import numpy as np
    from threadpoolctl import threadpool_limits

    if generations < 1 or warmup < 0 or pairs < 1 or k < 1:
        raise ValueError("generations, pairs and k must be >= 1 and warmup >= 0")
    results, skipped = [], []
    with threadpool_limits(limits=1):
        for n in sizes:
            for name in strategies:
                if name == "cmaes" and cmaes_bytes(n, 2 * pairs) > max_cmaes_gb * 1e9:
                    gb = cmaes_bytes(n, 2 * pairs) / 1e9
                    skipped.append({"strategy": name, "n": n, "reason": f"needs ~{gb:.1f} GB > "
                                    f"{max_cmaes_gb:g} GB (raise --cmaes-max-gb to run it)"})
                    continue
                results.append(time_strategy(name, n, generations, warmup, pairs, k, seed))
    return {
        "benchmark": "strategy_speed", "unit": "ms per generation (median)", "blas_threads": 1,
        "sizes": list(sizes), "strategies": list(strategies), "pairs": pairs, "popsize": 2 * pairs,
        "k": k, "generations": generations, "warmup": warmup, "results": results, "skipped": skipped,
        "numpy": np.__version__, "python": platform.python_version(), "machine": platform.machine(),
        "processor": platform.processor() or platform.machine(),
    }


def format_table(res: dict) -> str:
    """A readable table of :func:`bench_strategies`'s result."""
    head = f"{'strategy':<9} {'n':>10} {'ask ms':>9} {'tell ms':>9} {'guide ms':>9} {'gen ms':>9}  dtype"
    lines = [f"ES master per generation (population {res['popsize']}, k = {res['k']} surrogates for "
             f"guided, median of {res['generations']}, 1 BLAS thread)", head, "-" * len(head)]
    for r in res["results"]:
        guide = f"{r['guide_ms']:9.1f}" if "guide_ms" in r else f"{'-':>9}"
        lines.append(f"{r['strategy']:<9} {r['n']:>10,} {r['ask_ms']:9.1f} {r['tell_ms']:9.1f} {guide} "
                     f"{r['gen_ms']:9.1f}  {r['population_dtype']}")
    for s in res["skipped"]:
        lines.append(f"{s['strategy']:<9} {s['n']:>10,}  skipped: {s['reason']}")
    return "\n".join(lines)


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--sizes", type=parse_sizes, default=DEFAULT_SIZES,
                   help="comma-separated parameter counts (default: 2.4k,100k,1M)")
    p.add_argument("--strategies", type=parse_strategies, default=STRATEGY_NAMES,
                   help="comma-separated (default: vanilla,guided,cmaes)")
    p.add_argument("--generations", type=_count(1), default=5, help="timed generations (median reported)")
    p.add_argument("--warmup", type=_count(0), default=1, help="untimed generations first")
    p.add_argument("--pairs", type=_count(1), default=32, help="antithetic pairs (population = 2 x pairs)")
    p.add_argument("--k", type=_count(1), default=64, help="surrogate gradients per guide call (guided)")
    p.add_argument("--cmaes-max-gb", type=float, default=4.0, help="skip cmaes sizes estimated above this")
    p.add_argument("--json", action="store_true", help="one line of JSON")


def run_cli(a: argparse.Namespace) -> int:
    res = bench_strategies(a.sizes, a.strategies, generations=a.generations, warmup=a.warmup,
                           pairs=a.pairs, k=a.k, max_cmaes_gb=a.cmaes_max_gb)
    print(json.dumps(res) if a.json else format_table(res))
    return 0


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m shaped_es.speed.strategy_speed",
                                description=__doc__.splitlines()[0])
    add_arguments(p)
    return run_cli(p.parse_args(argv))


if __name__ == "__main__":
    raise SystemExit(main())
