"""What a benchmark will cost, printed before it starts: per method, seconds per generation and per run
and the whole, for the runs still to do, so that an expensive method (PPO: one "generation" is tens of
thousands of env steps on one core) is seen before it bites.

Per method, in order of preference:

- **measured**: runs of this benchmark that already have generations (a rerun): their own recent pace (the
  median of their last ``RECENT`` generations);
- **timed**: a short probe of the method's config (its first seed's) in a temporary directory on this
  machine, as it is loaded now: ES methods run ``PROBE_GENERATIONS`` generations (the pace of the
  generations after the first, whose start-up, worker pools and compiled kernels, is counted once per
  run); PPO runs two generations of one PPO iteration each without test episodes (the second is
  timed), and a generation is its iterations plus its test episodes at the probe's pace per env step.

ES episodes that end early cost less than ones running to the time limit, and policies that learn run
longer: the ES line therefore also gives the bound with every episode at its limit (``upper``).
"""

from __future__ import annotations

import contextlib
import io
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from shaped_es.config import RunConfig, build_config
from shaped_es.methods import METHODS, resolve
from shaped_es.rundir.store import RunStore

PROBE_GENERATIONS = 4
RECENT = 10  # generations of a run already begun whose pace its continuation is estimated at


@dataclass(frozen=True)
class Pace:
    """What one run of a method costs here."""

    startup_s: float  # once per run
    generation_s: float  # per generation, at the probe's pace
    upper_s: float  # per generation, every episode to its time limit (ES; PPO: the same)
    env_steps: int  # env steps of a generation at the probe's pace (PPO: exactly)
    source: str  # "measured" (this benchmark's runs) or "timed" (a probe)

    def run_s(self, generations: int, upper: bool = False) -> float:
        return (self.startup_s if generations else 0.0) + generations * (self.upper_s if upper else
                                                                           self.generation_s)


def measured_pace(cfg: RunConfig, stores: list[RunStore]) -> Pace | None:
    """The pace of a method's runs that already have generations (None if none has two)."""
    later, firsts = [], []
    for store in stores:
        rows = store.read_metrics() if store.exists() else []
        # the last RECENT generations: a run continued goes on at its recent pace (a new user's shaped runs,
        # extended from 40 to 80 generations, were estimated at 10 min from all 40 and took 4.3: the label
        # probe's and the early awake generations' seconds, which a later generation no longer pays)
        later += [r for r in rows[max(1, len(rows) - RECENT):] if r.get("gen_time_s") not in (None, "")]
        firsts += [float(rows[0]["gen_time_s"])] if rows and rows[0].get("gen_time_s") not in (None, "") else []
    if not later:
        return None
    per_gen = statistics.median(float(r["gen_time_s"]) for r in later)
    startup = max(0.0, statistics.median(firsts) - per_gen)  # the first generation beyond the others
    return _pace(cfg, startup, per_gen, later, "measured")


def _pace(cfg: RunConfig, startup: float, per_gen: float, rows: list[dict], source: str) -> Pace:
    """``Pace`` from the seconds per generation and the rows of generations after the first (ES: the
    upper bound scales their rollouts to every episode running to its time limit)."""
    steps = statistics.median(float(r["gen_env_steps"]) for r in rows)
    upper = per_gen
    if METHODS[cfg.method].strategy is not None:
        rollout = statistics.median(float(r["rollout_time_s"]) for r in rows)
        budget = 2 * cfg.es.pairs * cfg.rollout.episodes * _horizon(cfg)
        upper += rollout * max(0.0, budget / max(steps, 1.0) - 1.0)
    return Pace(startup, per_gen, upper, int(steps), source)


def _horizon(cfg: RunConfig) -> int:
    from shaped_es.rollout import probe_env

    limit = probe_env(cfg.env, cfg.env_kwargs).time_limit
    caps = [h for h in (cfg.rollout.max_steps, limit) if h]
    return min(caps) if caps else 1000


def timed_pace(cfg: RunConfig) -> Pace:
    """A probe of ``cfg`` in a temporary run directory (see the module docstring)."""
    probe = cfg.model_dump(mode="json")
    probe.update(tensorboard=False, stop_at=None, keep_checkpoints=1)
    probe["wandb"] = {**probe["wandb"], "enabled": False}
    if METHODS[cfg.method].strategy is None:
        return _ppo_pace(cfg, probe)
    probe["generations"] = PROBE_GENERATIONS
    marks, rows = _probe(build_config(probe))
    per_gen = statistics.median(b - a for a, b in zip(marks[:-2], marks[1:-1]))  # whole generations
    lag = 2 if cfg.eval_overlap and cfg.rollout.test_episodes else 1  # overlapped tests: rows come later
    startup = max(0.0, marks[0] - lag * per_gen)
    return _pace(cfg, startup, per_gen, rows[1:], "timed")


def _ppo_pace(cfg: RunConfig, probe: dict) -> Pace:
    from shaped_es.baselines.ppo_settings import iterations_per_generation, ppo_settings

    s = ppo_settings(cfg)
    horizon = _horizon(cfg)
    iterations = iterations_per_generation(cfg, s, horizon)
    one = s.n_steps * s.n_envs
    probe["generations"] = 2  # of one iteration each: the second is timed (the first warms torch up)
    probe["ppo"] = {**probe["ppo"], "steps_per_generation": one}
    probe["rollout"] = {**probe["rollout"], "test_episodes": 0}
    marks, rows = _probe(build_config(probe))
    iteration = float(rows[1]["gen_time_s"])
    per_step = float(rows[1]["rollout_time_s"]) / one  # env + policy, as the test episodes step
    per_gen = iterations * iteration + cfg.rollout.test_episodes * horizon * per_step
    startup = max(0.0, marks[-1] - 2 * iteration)
    return Pace(startup, per_gen, per_gen, iterations * one, "timed")


def _probe(cfg: RunConfig) -> tuple[list[float], list[dict]]:
    """Run ``cfg`` in a temporary directory; the seconds from the start at which each metrics row came,
    and the rows."""
    marks: list[float] = []
    t0 = time.perf_counter()
    # its lines (a shaped run's label probe, a back-off note) are the real runs' to print: not twice
    with tempfile.TemporaryDirectory(prefix="shaped-es-estimate-") as tmp, contextlib.redirect_stderr(io.StringIO()):
        store = RunStore(Path(tmp) / "run")
        store.create(cfg)
        rows = resolve(METHODS[cfg.method].train)(
            cfg, store, progress=False, callback=lambda row: marks.append(time.perf_counter() - t0))
    return marks, rows


def estimate(labels: dict[str, list[tuple[RunConfig, RunStore, int]]]) -> dict[str, dict]:
    """Per method label: its runs as (config, store, generations left), the pace and the seconds left."""
    out = {}
    for label, runs in labels.items():
        left = [(cfg, store, n) for cfg, store, n in runs if n > 0]
        if not left:
            out[label] = {"runs": 0, "generations": 0, "seconds": 0.0, "upper_seconds": 0.0, "pace": None}
            continue
        pace = measured_pace(left[0][0], [s for _, s, _ in runs]) or timed_pace(left[0][0])
        out[label] = {"runs": len(left), "generations": sum(n for _, _, n in left), "pace": pace,
                      "seconds": sum(pace.run_s(n) for _, _, n in left),
                      "upper_seconds": sum(pace.run_s(n, upper=True) for _, _, n in left)}
    return out


def describe(est: dict[str, dict]) -> list[str]:
    """The estimate as the lines the benchmark prints (one per method, then the total)."""
    lines = []
    for label, e in est.items():
        p: Pace | None = e["pace"]
        if p is None:
            lines.append(f"{label}: nothing left to run")
            continue
        how = "measured on this benchmark's runs" if p.source == "measured" else "timed just now"
        up = (f" (up to {duration(e['upper_seconds'])} if every episode runs to its time limit)"
              if _more(e["upper_seconds"], e["seconds"]) else "")
        gens = f"{e['generations']} generation{'s' * (e['generations'] != 1)}"
        lines.append(f"{label}: {e['runs']} run{'s' * (e['runs'] != 1)}, {gens} at {p.generation_s:,.2f} s "
                     f"each (~{p.env_steps:,} env steps, {how}) -> ~{duration(e['seconds'])}{up}")
    total = sum(e["seconds"] for e in est.values())
    upper = sum(e["upper_seconds"] for e in est.values())
    big = max(est, key=lambda k: est[k]["seconds"], default=None)
    share = f"; {big} {est[big]['seconds'] / total:.0%} of it" if big and total > 0 else ""
    lines.append(f"total ~{duration(total)}" + (f" (up to {duration(upper)})" if _more(upper, total) else "")
                 + share)
    return lines


def _more(upper: float, point: float) -> bool:
    """The bound is worth a mention: over 1.2x the point estimate, and different when printed."""
    return upper > 1.2 * point and duration(upper) != duration(point)


def duration(s: float) -> str:
    """Seconds in words: '45 s', '12 min', '3.4 h'."""
    if s < 90:
        return f"{s:.0f} s"
    if s < 5400:
        return f"{s / 60:.0f} min"
    return f"{s / 3600:.1f} h"


def benchmark_estimate(plan: dict[str, tuple[str, RunConfig]], runs_dir: Path, label_of) -> dict[str, dict]:
    """:func:`estimate` of a benchmark's plan (``plan.plan_runs``); ``label_of(run name)``: its method
    label. Finished runs cost nothing; a reused run only its generations left."""
    from shaped_es.run_loop import run_finished

    labels: dict[str, list] = {}
    for name, (action, cfg) in plan.items():
        store = RunStore(runs_dir / name)
        done = 0 if action != "reuse" else (cfg.generations if run_finished(cfg, store) else
                                           store.newest_generation())
        labels.setdefault(label_of(name), []).append((cfg, store, max(0, cfg.generations - done)))
    return estimate(labels)
