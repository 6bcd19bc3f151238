"""Run every (method, seed) of a benchmark into ``DIR/runs/<method>_s<seed>/``, resumably, then report.

Layout::

    DIR/benchmark.yaml                 the benchmark's settings (the latest invocation)
    DIR/runs/<method>_s<seed>/         one ordinary run directory each (train/resume/evaluate work on it)
    DIR/summary.json, DIR/report.md    across-seed statistics and the report (``markdown.py``)
    DIR/figures/                       Fig. 4, the performance profile (profile_final_reward.png) and
                                       Fig. 5 when the shaped runs log M_phi losses

A rerun skips runs whose newest checkpoint reached ``generations`` and resumes unfinished ones (the
trainer and PPO restore their newest checkpoint). Settings are compared per run, on the fields that run's
method uses (:func:`method_digest`: ``ppo.*`` only matter to PPO, ``shaping.*`` only to ``shaped``, ...),
so a rerun with changed settings of one method reuses every other method's runs. A run whose own
settings changed is started afresh if it has no checkpoint yet; one with finished generations is
refused, before any run starts, in one line naming those runs (delete them to redo them with the new
settings). Every config is validated (``preflight.check_run``) before anything is written. Runs go seed
by seed, every method within a seed, so a partial benchmark compares methods on the same seeds.
Ablations (the paper's commented-out sparse-waypoint figure, and alpha / eta): ``sparse_waypoints``
multiplies the env's ``waypoint_spacing`` by 10 (planner resolution / 10). Variants
(``--variant lean=shaped,shaping.cloning.steps=5``) are named settings of a method, compared as methods
of their own (``DIR/runs/lean_s0/``).
"""

from __future__ import annotations

import inspect
import json
import sys
import time
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path

import yaml

from shaped_es.config import ConfigError, RunConfig, build_config, merge
from shaped_es.methods import METHODS, resolve
from shaped_es.run_loop import run_finished
from shaped_es.rundir.meta import RUNTIME_FIELDS
from shaped_es.rundir.run_files import replace_run_dir
from shaped_es.rundir.atomic import clean_stale_temporaries
from shaped_es.rundir.store import RunStore, StoreError, StoreWarning, atomic_write_text

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


def _first_difference(a: RunConfig, b: RunConfig) -> str:
    da, db = _flat(_relevant(a)), _flat(_relevant(b))
    diff = sorted(k for k in set(da) | set(db) if da.get(k) != db.get(k))
    return ", ".join(diff[:3]) or "?"


def _flat(d: dict, prefix: str = "") -> dict:
    out = {}
    for k, v in d.items():
        out.update(_flat(v, f"{prefix}{k}.") if isinstance(v, dict) and v else {f"{prefix}{k}": v})
    return out


# ``es`` fields a method never reads (trainer.build_strategy / build_guide, ppo_settings.horizon);
# anything not listed here counts, so a new field is compared until it is known to be irrelevant.
def _relevant(cfg: RunConfig) -> dict:
    """The config as JSON with the sections and ``es`` fields ``cfg.method`` never reads (``Method.reads``)
    reset to their defaults (``ppo`` reads only ``es.pairs``, for its env-step budget)."""
    d = cfg.model_dump(mode="json")
    defaults = RunConfig().model_dump(mode="json")
    reads = METHODS[cfg.method].reads
    for section in ("es", "shaping", "ppo"):
        if section not in reads:
            d[section] = {k: (v if f"{section}.{k}" in reads else defaults[section][k])
                          for k, v in d[section].items()}
    return d


def method_digest(cfg: RunConfig) -> str:
    """Hash of the settings that determine this run's results given its method."""
    from shaped_es.rundir.meta import config_digest

    return f"{cfg.method}:{config_digest(build_config(_relevant(cfg)))}"


def _reuse(old: RunConfig, new: RunConfig) -> RunConfig:
    """``old`` (the run's own config: its checkpoints were made with it) with this invocation's
    execution settings (generations, executor, workers, ...)."""
    d = old.model_dump(mode="json")
    nd = new.model_dump(mode="json")
    return build_config({**d, **{k: nd[k] for k in RUNTIME_FIELDS if k in nd}})


def plan_runs(cfgs: dict[str, RunConfig], runs_dir: Path) -> dict[str, tuple[str, RunConfig]]:
    """Per run: ``("new" | "restart" | "reuse", config to run with)``; refuses (``StoreError``, one line
    naming every such run) runs with finished generations whose own settings changed."""
    plan, changed, other_env = {}, [], []  # other_env: the envs of changed runs made on another env
    for name, cfg in cfgs.items():
        store = RunStore(runs_dir / name)
        if not store.exists():
            plan[name] = ("new", cfg)
            continue
        old = store.read_config()
        if old.method == cfg.method and method_digest(old) == method_digest(cfg):
            plan[name] = ("reuse", _reuse(old, cfg))
        elif not store.checkpoints():
            plan[name] = ("restart", cfg)  # nothing done yet (e.g. a run that failed to start)
        else:
            changed.append((name, _first_difference(old, cfg)))
            other_env += [old.env] if old.env != cfg.env else []
    if changed and len(other_env) == len(changed):  # a folder of another env's study, not changed settings
        envs = ", ".join(sorted(set(other_env)))
        env = next(iter(cfgs.values())).env
        raise StoreError(f"{runs_dir.parent} holds a benchmark of another env ({envs}), not {env}: a benchmark "
                         f"folder is one env's; use another --out")
    if changed:
        names = ", ".join(n for n, _ in changed)
        fields = ", ".join(sorted({f for _, d in changed for f in d.split(", ")})[:3])
        others = "the other runs are reused: " if plan else ""
        raise StoreError(f"runs {names} in {runs_dir} hold a different config ({fields}) with finished "
                         f"generations; {others}delete those to redo them with these settings, or use another "
                         f"--out")
    if cfgs:
        warn_env_edited(runs_dir, [n for n, (act, _) in plan.items() if act == "reuse"], next(iter(cfgs.values())).env)
    return plan


def warn_env_edited(runs_dir: Path, names: list[str], env_id: str) -> None:
    """One warning line naming the reused runs made on an earlier version of the env's module (its source hash
    in their ``run.json`` differs: ``rundir/env_source.py``): a rerun reuses them as they are."""
    from shaped_es.rundir.env_source import fingerprint

    now = fingerprint(env_id)  # hashed once, compared with each run's
    if now is None:
        return
    edited = [n for n in names if RunStore(runs_dir / n).env_changed(env_id, now)]
    if not edited:
        return
    file = Path(now["file"]).name
    shown = ", ".join(edited[:4]) + (f" and {len(edited) - 4} more" if len(edited) > 4 else "")
    warnings.warn(f"{file} changed since runs {shown} in {runs_dir} were made: they are reused as they are (their "
                  f"results are the earlier env's); delete them, or use another --out, to redo them on the env as "
                  f"it is now", StoreWarning, stacklevel=2)


def run_one(cfg: RunConfig, root: Path, progress: bool = False, action: str | None = None) -> str:
    """Train, resume or skip one run; returns 'new', 'resumed' or 'skipped'. ``action`` (from
    :func:`plan_runs`; None plans this run alone) says whether ``root`` is new, to restart or to reuse."""
    store = RunStore(root)
    if action is None:
        action, cfg = plan_runs({root.name: cfg}, root.parent)[root.name]
    if action == "reuse":
        if run_finished(cfg, store):  # every generation done, or stopped at --stop-at
            return "skipped"
        status = "resumed"  # more generations, or another executor: the run loop saves them once restored
    else:
        if action == "restart":  # a run directory without a checkpoint: only the run's own files go
            replace_run_dir(store.root)
        store.create(cfg)
        status = "new"
    with store.lock():  # held for the whole run (PPO included), not only around each write
        from shaped_es.trained.video import with_video

        resolve(METHODS[cfg.method].train)(cfg, store, progress=progress, callback=with_video(cfg, progress=progress))
    return status


def _check_all(cfgs: dict[str, RunConfig]) -> None:
    """``preflight.check_run`` once per method or variant (the seed does not change what is checked; a
    variant's settings may, e.g. its ``shaping.labels``). No warnings of settings a method ignores: a
    benchmark's settings are shared by its methods on purpose."""
    from shaped_es.preflight import check_run

    seen = set()
    for cfg in cfgs.values():
        key = json.dumps({**cfg.model_dump(mode="json"), "seed": 0}, sort_keys=True)
        if key not in seen:
            seen.add(key)
            check_run(cfg, warn=False)


def check_own_folder(out: Path, mark: str, what: str) -> None:
    """A benchmark (suite) directory is its own: refuse (``StoreError``) an existing folder without ``mark``
    (``benchmark.yaml``, ``suite.yaml``) that holds anything but ``runs/``: its report would land beside them."""
    if out.exists() and not out.is_dir():
        raise StoreError(f"--out {out} exists and is not a directory")
    if not out.is_dir() or (out / mark).exists():
        return
    try:
        names = sorted(p.name for p in out.iterdir() if p.name != "runs" or not p.is_dir())
    except OSError as exc:
        raise StoreError(f"cannot list --out {out}: {exc.strerror or exc}") from None
    if names:
        shown = ", ".join(names[:3]) + (", ..." if len(names) > 3 else "")
        raise StoreError(f"--out {out} is a folder that holds no {what} but other files ({shown}); a {what} "
                         f"directory is the {what}'s own: name a new or empty folder")


def _longer(groups: dict[str, list[Path]], generations: int) -> list[tuple[str, int]]:
    """``(name, rows)`` of the runs with more rows than ``generations`` (extended by an earlier invocation with a
    larger budget)."""
    out = []
    for dirs in groups.values():
        for d in dirs:
            try:
                n = len(RunStore(d).read_metrics())
            except (OSError, StoreError, ValueError):
                continue
            if n > generations:
                out.append((d.name, n))
    return out


def _outcome(cfg: RunConfig, root: Path, threshold: float | None = None) -> str:
    """``, last test reward 8.67``, where it reached the threshold (:func:`_reached`), and
    for a candidate run ``; candidates accepted 3 of 23 judged``, or ``; no candidate accepted ...`` where its
    labels never paid (``train`` prints the long form at a run's end); new users' benchmarks showed neither
    until the report. ``""`` where the run has no rows."""
    from shaped_es.guides.label_budget import never_accepted, rows_summary, run_cost

    try:
        rows = RunStore(root).read_metrics()
    except (OSError, StoreError, ValueError):
        return ""
    last = rows[-1].get("test_reward_mean") if rows else None
    try:
        out = f", last test reward {float(last):.2f}" if last not in (None, "") else ""
    except (TypeError, ValueError):
        out = ""
    out += _reached(cfg, root, threshold) if rows else ""
    summary = rows_summary(rows)
    if summary is not None:
        summary["cost"] = run_cost(rows, root)  # about what shaping cost the run (None: no price)
    never = never_accepted(summary, METHODS[cfg.method].base, short=True)
    if never:
        return out + f"; {never}"
    if summary and summary["candidates_judged"]:  # what shaping did, as the progress bar's "labels A/J"
        out += f"; candidates accepted {summary['candidates_accepted']} of {summary['candidates_judged']} judged"
        if summary.get("check_lost"):  # check_episodes: winners the check did not bear out
            out += f" ({summary['check_lost']} more won and lost the check)"
    return out


def _reached(cfg: RunConfig, root: Path, threshold: float | None) -> str:
    """``, 8.5 reached at generation 4`` (generations done: ``summary.first_reach``, as ``train``'s final JSON
    counts them), or ``""``: the threshold ``benchmark`` and ``report`` use (``threshold``, else the env's)."""
    from shaped_es.benchmark.summary import first_reach, threshold_of
    from shaped_es.report.plots import load_metrics

    if threshold is None:
        found = threshold_of(cfg.env, cfg.env_kwargs)
        threshold = found[0] if found else None
    metrics = load_metrics(root) if threshold is not None else None
    hit = first_reach(metrics, threshold) if metrics else None
    if hit:
        return f", {threshold:g} reached at generation {hit['generations']:.0f}"
    return f", {threshold:g} not reached" if metrics else ""  # a new user read the missing clause as nothing


def run_benchmark(spec: BenchmarkSpec, out: str | Path, progress: bool = False, log=None,
                  estimate: bool = True, estimate_only: bool = False) -> dict:
    """Run (or continue) every run of ``spec`` under ``out``, then write summary.json and report.md;
    ``estimate``: first print what the runs left will cost (``estimate.py``: a short probe per method);
    ``estimate_only``: print it and stop, writing nothing."""
    from shaped_es.benchmark.markdown import write_report

    log = log or (lambda msg: print(msg, file=sys.stderr, flush=True))
    out = Path(out)
    check_own_folder(out, "benchmark.yaml", "benchmark")
    cfgs = run_configs(spec)
    _check_all(cfgs)
    plan = plan_runs(cfgs, out / "runs")
    for name in plan:  # a run another process is writing: refused now, before the estimate's timing
        store = RunStore(out / "runs" / name)
        if store.root.is_dir():
            with store.lock():
                pass
    if estimate or estimate_only:
        from shaped_es.benchmark.estimate import benchmark_estimate, describe

        labels = {run_name(m, s): m for s in spec.seeds for m in spec.methods}
        est = benchmark_estimate(plan, out / "runs", labels.__getitem__)
        for line in describe(est):
            log(f"[benchmark] estimate: {line}")
        if estimate_only:
            return {"estimate_s": {k: round(e["seconds"], 1) for k, e in est.items()}}
    out.mkdir(parents=True, exist_ok=True)
    record = json.loads(json.dumps(asdict(spec)))  # tuples -> lists for YAML
    clean_stale_temporaries(out, ("benchmark.yaml",))  # a killed invocation's
    atomic_write_text(out / "benchmark.yaml", yaml.safe_dump(record, sort_keys=False))
    status: dict[str, dict] = {}
    for name, (action, cfg) in plan.items():
        t0 = time.perf_counter()
        s = run_one(cfg, out / "runs" / name, progress=progress, action=action)
        status[name] = {"status": s, "seconds": round(time.perf_counter() - t0, 3)}
        log(f"[benchmark] {name}: {s} ({status[name]['seconds']:.1f} s)"
            f"{_outcome(cfg, out / 'runs' / name, spec.threshold)}")
    groups = {m: [out / "runs" / run_name(m, s) for s in spec.seeds] for m in spec.methods}
    configs = {m: cfgs[run_name(m, spec.seeds[0])] for m in spec.methods}
    extra = {"benchmark": record, "this_invocation": status}
    paths = write_report(out / "report.md", groups, configs, generations=spec.generations,
                         title=f"Benchmark on {spec.env}", extra=extra, threshold=spec.threshold)
    from shaped_es.benchmark.verdict import verdict_lines

    for line in verdict_lines(json.loads(Path(paths["summary"]).read_text()), str(out)):  # the report's verdict
        log(f"[benchmark] {line}")
    longer = _longer(groups, spec.generations)
    if longer:  # a rerun with a smaller budget: the page cuts the runs there, the run lines above did not
        named = ", ".join(f"{name} ({n} generations)" for name, n in longer[:4])
        log(f"[benchmark] report.md reads every run up to generation {spec.generations} (this --generations); "
            f"longer: {named}{' ...' if len(longer) > 4 else ''}: their lines above are their last rows; "
            f"--generations {max(n for _, n in longer)} (or shaped-es report, which reads each run to its end) "
            f"uses them whole")
    shown = {d.name for dirs in groups.values() for d in dirs}
    left = sorted(p.name for p in (out / "runs").iterdir() if p.is_dir() and p.name not in shown)
    if left:  # a rerun with fewer methods or seeds: its page shows this invocation's runs only
        log(f"[benchmark] report.md shows this invocation's methods and seeds; {out / 'runs'} also holds "
            f"{', '.join(left[:4])}{' ...' if len(left) > 4 else ''} ({len(left)}): shaped-es report {out} "
            f"--out {out / 'report.md'} draws them all")
    return {**paths, "runs": status}
