"""Run every (method, seed) of a benchmark into ``DIR/runs/<method>_s<seed>/``, resumably, then report.

Layout::

    DIR/benchmark.yaml                 the benchmark's settings (the latest invocation)
    DIR/runs/<method>_s<seed>/         one ordinary run directory each (train/resume/evaluate work on it)
    DIR/summary.json, DIR/report.md    across-seed statistics and the report (``markdown.py``)
    DIR/figures/                       Fig. 4, the performance profile (profile_final_reward.png) and
                                       Fig. 5 when the shaped runs log M_phi losses

What a benchmark runs (its settings, its runs' configs, ablations and variants) is ``spec.py``'s; what a rerun
does with each run directory, ``plan.py``'s. A rerun skips runs whose newest checkpoint reached
``generations`` and resumes unfinished ones (the trainer and PPO restore their newest checkpoint); a run whose
own settings changed is started afresh if it has no checkpoint yet and refused, before any run starts, if it
has finished generations. Every config is validated (``preflight.check_run``) before anything is written.
Runs go seed by seed, every method within a seed, so a partial benchmark compares methods on the same seeds.
"""

from __future__ import annotations

import json
import sys
import time
from dataclasses import asdict
from pathlib import Path

import yaml

from shaped_es.benchmark.plan import plan_runs
from shaped_es.benchmark.spec import BenchmarkSpec, run_configs, run_name
from shaped_es.config import RunConfig
from shaped_es.methods import METHODS, resolve
from shaped_es.run_loop import run_finished
from shaped_es.rundir.run_files import replace_run_dir
from shaped_es.rundir.atomic import clean_stale_temporaries
from shaped_es.rundir.store import RunStore, StoreError, atomic_write_text


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
    for a candidate run ``; candidates accepted 3 of 23 judged (own labels 1, shooting 2)``, or ``; no
    candidate accepted ...`` where its labels never paid (``train`` prints the long form at a run's end); new
    users' benchmarks showed neither until the report. ``""`` where the run has no rows."""
    from shaped_es.guides.label_budget import by_source, never_accepted, rows_summary, run_cost

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
        out += (f"; candidates accepted {summary['candidates_accepted']} of {summary['candidates_judged']} judged"
                f"{by_source(summary)}")  # whose clones they were, as train's closing line says
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
