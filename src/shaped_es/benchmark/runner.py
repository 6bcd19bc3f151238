"""Run every (method, seed) of a benchmark into ``DIR/runs/<method>_s<seed>/``, resumably, then report.

Layout::

    DIR/benchmark.yaml                 the benchmark's settings (the latest invocation)
    DIR/runs/<method>_s<seed>/         one ordinary run directory each (train/resume/evaluate work on it)
    DIR/summary.json, DIR/report.md    across-seed statistics and the report (``markdown.py``)
    DIR/figures/                       Fig. 4 (and Fig. 5 when the shaped runs log M_phi losses)

A rerun skips runs whose newest checkpoint reached ``generations``, resumes unfinished ones (the
trainer and PPO restore their newest checkpoint) and refuses a run directory holding a different
config. Runs go seed by seed, every method within a seed, so a partial benchmark compares methods on
the same seeds. Ablations (the paper's commented-out sparse-waypoint figure, and alpha / eta):
``sparse_waypoints`` multiplies the env's ``waypoint_spacing`` by 10 (planner resolution / 10).
"""

from __future__ import annotations

import inspect
import json
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

import yaml

from shaped_es.config import METHODS, ConfigError, RunConfig, build_config, dump_config, merge
from shaped_es.store import RunStore, StoreError, atomic_write_text

SPARSE_FACTOR = 10.0  # paper: global planner resolution / 10 -> waypoints 10x further apart
SPACING_KEY = "waypoint_spacing"


@dataclass(frozen=True)
class BenchmarkSpec:
    env: str  # Gymnasium id of every run
    methods: tuple[str, ...]  # methods to compare, run in this order within a seed
    seeds: tuple[int, ...]  # root seeds; one run per (method, seed)
    generations: int  # generations per run (PPO: iterations of the matched env-step budget)
    base: dict = field(default_factory=dict)  # config fields from a YAML file (lowest precedence)
    overrides: dict = field(default_factory=dict)  # dotted overrides (--preset, --set, --executor, ...)
    sparse_waypoints: bool = False  # ablation: waypoint_spacing x SPARSE_FACTOR
    alpha: float | None = None  # ablation: es.alpha (Guided-ES isotropic share)
    eta: float | None = None  # ablation: shaping.eta (surrogate normalization)

    def __post_init__(self):
        unknown = [m for m in self.methods if m not in METHODS]
        if unknown or not self.methods:
            raise ConfigError(f"--methods: unknown {unknown or 'empty list'}; choose from {', '.join(METHODS)}")
        if len(set(self.methods)) != len(self.methods):
            raise ConfigError(f"--methods: repeated method in {','.join(self.methods)}")
        if not self.seeds or len(set(self.seeds)) != len(self.seeds) or min(self.seeds) < 0:
            raise ConfigError("--seeds: need one or more distinct non-negative seeds")
        if self.generations <= 0:
            raise ConfigError(f"--generations must be positive, got {self.generations}")


def run_name(method: str, seed: int) -> str:
    return f"{method}_s{seed}"


def sparse_waypoint_kwargs(env_id: str, env_kwargs: dict) -> dict:
    """``env_kwargs`` with the env's effective ``waypoint_spacing`` multiplied by ``SPARSE_FACTOR``."""
    if SPACING_KEY in env_kwargs:
        spacing = env_kwargs[SPACING_KEY]
    else:
        spacing = _effective_spacing(env_id, env_kwargs)
    if not isinstance(spacing, (int, float)) or spacing <= 0:
        raise ConfigError(f"--sparse-waypoints: env {env_id} does not support a '{SPACING_KEY}' setting "
                          f"(built-in: CarNav-v0)")
    return {**env_kwargs, SPACING_KEY: float(spacing) * SPARSE_FACTOR}


def _effective_spacing(env_id: str, env_kwargs: dict):
    """The spacing the env uses with these kwargs: an attribute of the env or of its config object, else
    the constructor's default; None if the env has no such setting."""
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.rollout import make_env

    env = make_env(env_id, env_kwargs)
    try:
        u = env.unwrapped
        for holder in (u, *vars(u).values()):  # the env, or a config object/dict it holds
            v = holder.get(SPACING_KEY) if isinstance(holder, dict) else getattr(holder, SPACING_KEY, None)
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                return v
        p = inspect.signature(type(u).__init__).parameters.get(SPACING_KEY)
        return None if p is None or p.default is inspect.Parameter.empty else p.default
    finally:
        env.close()


def run_configs(spec: BenchmarkSpec) -> dict[str, RunConfig]:
    """One validated config per run, keyed by run name, in run order (seed-major)."""
    common = merge(spec.base, {**spec.overrides, "env": spec.env, "generations": spec.generations})
    if spec.alpha is not None:
        common = merge(common, {"es.alpha": spec.alpha})
    if spec.eta is not None:
        common = merge(common, {"shaping.eta": spec.eta})
    if spec.sparse_waypoints:
        common["env_kwargs"] = sparse_waypoint_kwargs(spec.env, dict(common.get("env_kwargs") or {}))
    return {run_name(m, s): build_config(merge(common, {"method": m, "seed": s}))
            for s in spec.seeds for m in spec.methods}


def finished_generations(store: RunStore) -> int:
    """Generations covered by the run's newest complete checkpoint (0 without one)."""
    latest = store.ckpt_dir / "latest.json"
    if not latest.is_file():
        return 0
    try:
        name = json.loads(latest.read_text())["name"]
        return int(json.loads((store.ckpt_dir / f"{name}.json").read_text())["generation"])
    except (OSError, KeyError, ValueError, TypeError) as exc:
        raise StoreError(f"checkpoint in {store.ckpt_dir} is unreadable: {type(exc).__name__}") from None


def _first_difference(a: RunConfig, b: RunConfig) -> str:
    da, db = _flat(a.model_dump(mode="json")), _flat(b.model_dump(mode="json"))
    diff = sorted(k for k in set(da) | set(db) if da.get(k) != db.get(k))
    return ", ".join(diff[:3]) or "?"


def _flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        out.update(_flat(v, f"{prefix}{k}.") if isinstance(v, dict) and v else {f"{prefix}{k}": v})
    return out


def run_one(cfg: RunConfig, root: Path, progress: bool = False) -> str:
    """Train, resume or skip one run; returns 'new', 'resumed' or 'skipped'."""
    from shaped_es.trainer import config_digest

    store = RunStore(root)
    if store.exists():
        old = store.read_config()
        if config_digest(old) != config_digest(cfg) or old.method != cfg.method:
            raise StoreError(f"{root} holds a run with a different config ({_first_difference(old, cfg)}); "
                             "use another --out")
        if finished_generations(store) >= cfg.generations:
            return "skipped"
        if old != cfg:  # more generations, or another executor / worker count
            atomic_write_text(store.config_path, dump_config(cfg))
        status = "resumed"
    else:
        store.create(cfg)
        status = "new"
    if cfg.method == "ppo":
        from shaped_es.baselines.ppo import train_ppo

        train_ppo(cfg, store, progress=progress)
    else:
        from shaped_es.trainer import Trainer

        Trainer(cfg, store, progress=progress).run()
    return status


def _check_env(cfg: RunConfig) -> None:
    import shaped_es  # noqa: F401 - registers the built-in envs
    from shaped_es.rollout import env_dims, make_env

    env = make_env(cfg.env, cfg.env_kwargs)
    try:
        env_dims(env)
    finally:
        env.close()


def run_benchmark(spec: BenchmarkSpec, out: str | Path, progress: bool = False, log=None) -> dict:
    """Run (or continue) every run of ``spec`` under ``out``, then write summary.json and report.md."""
    from shaped_es.benchmark.markdown import write_report

    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise StoreError(f"--out {out} exists and is not a directory")
    cfgs = run_configs(spec)
    _check_env(next(iter(cfgs.values())))
    out.mkdir(parents=True, exist_ok=True)
    record = json.loads(json.dumps(asdict(spec)))  # tuples -> lists for YAML
    atomic_write_text(out / "benchmark.yaml", yaml.safe_dump(record, sort_keys=False))
    status: dict[str, dict] = {}
    for name, cfg in cfgs.items():
        t0 = time.perf_counter()
        s = run_one(cfg, out / "runs" / name, progress=progress)
        status[name] = {"status": s, "seconds": round(time.perf_counter() - t0, 3)}
        log(f"[benchmark] {name}: {s} ({status[name]['seconds']:.1f} s)")
    groups = {m: [out / "runs" / run_name(m, s) for s in spec.seeds] for m in spec.methods}
    configs = {m: cfgs[run_name(m, spec.seeds[0])] for m in spec.methods}
    extra = {"benchmark": record, "this_invocation": status}
    paths = write_report(out / "report.md", groups, configs, generations=spec.generations,
                         title=f"Benchmark on {spec.env}", extra=extra)
    return {**paths, "runs": status}
