"""What a benchmark runs: its settings (:class:`BenchmarkSpec`, ``DIR/benchmark.yaml``), its runs' names
(``<method>_s<seed>``, :func:`run_name`) and one validated config per run (:func:`run_configs`), in run order:
seed by seed, every method within a seed, so a partial benchmark compares methods on the same seeds.

Ablations (the paper's commented-out sparse-waypoint figure, and alpha / eta): ``sparse_waypoints``
multiplies the env's ``waypoint_spacing`` by 10 (planner resolution / 10). Variants
(``--variant lean=shaped,shaping.cloning.steps=5``) are named settings of a method, compared as methods
of their own (``DIR/runs/lean_s0/``).
"""

from __future__ import annotations

import inspect
from dataclasses import dataclass, field

from shaped_es.config import ConfigError, RunConfig, build_config, merge
from shaped_es.methods import METHODS

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
    threshold: float | None = None  # success threshold of the report (None: the env's default)
    # named variants usable in ``methods``: label -> {"method": base method, dotted overrides...}
    variants: dict = field(default_factory=dict)

    def method_of(self, label: str) -> str:
        return self.variants[label]["method"] if label in self.variants else label

    def __post_init__(self):
        for label, v in self.variants.items():
            if label in METHODS or not label or "/" in label or not isinstance(v, dict) \
                    or v.get("method") not in METHODS:
                raise ConfigError(f"--variant {label!r}: needs a new name (not a method) and a base method "
                                  f"from {', '.join(METHODS)}")
        unknown = [m for m in self.methods if self.method_of(m) not in METHODS]
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
    from shaped_es.rollout import close_env, make_env

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
        close_env(env)


def run_configs(spec: BenchmarkSpec) -> dict[str, RunConfig]:
    """One validated config per run, keyed by run name, in run order (seed-major)."""
    common = merge(spec.base, {**spec.overrides, "env": spec.env, "generations": spec.generations})
    if spec.alpha is not None:
        common = merge(common, {"es.alpha": spec.alpha})
    if spec.eta is not None:
        common = merge(common, {"shaping.eta": spec.eta})
    if spec.sparse_waypoints:
        common["env_kwargs"] = sparse_waypoint_kwargs(spec.env, dict(common.get("env_kwargs") or {}))
    def one(label: str, seed: int) -> RunConfig:
        extra = {k: v for k, v in spec.variants.get(label, {}).items() if k != "method"}
        return build_config(merge(merge(common, extra), {"method": spec.method_of(label), "seed": seed}))

    return {run_name(m, s): one(m, s) for s in spec.seeds for m in spec.methods}
