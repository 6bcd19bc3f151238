"""The benchmark's cost estimate: a timed probe per method (ES generations; PPO iterations scaled to its
generation), the pace of a rerun's own runs, finished runs costing nothing, and the lines it prints.
Nothing here asserts a speed: only that the estimate is made of what it says."""

import json
import pytest

from helpers import CARTPOLE_TINY, train
from shaped_es.benchmark.estimate import (Pace, benchmark_estimate, describe, duration, measured_pace,
                                          timed_pace)
from shaped_es.config import build_config
from shaped_es.rundir.store import RunStore

ES = {**CARTPOLE_TINY, "executor": "inline", "rollout": {"episodes": 2, "test_episodes": 3, "max_steps": 50}}
PPO = {**ES, "method": "ppo", "ppo": {"n_steps": 64, "batch_size": 32, "n_epochs": 1}}


def test_an_es_probe_times_generations_and_bounds_full_episodes():
    cfg = build_config(ES)
    pace = timed_pace(cfg)
    assert pace.source == "timed" and pace.generation_s > 0 and pace.startup_s >= 0
    assert 0 < pace.env_steps <= 2 * 8 * 2 * 50  # a generation's env steps, at most the budget
    assert pace.upper_s >= pace.generation_s  # every episode to its limit costs at least as much
    assert pace.run_s(10) == pytest.approx(pace.startup_s + 10 * pace.generation_s)


def test_a_ppo_probe_scales_one_iteration_to_its_generation():
    cfg = build_config(PPO)
    pace = timed_pace(cfg)
    # the budget 2 x 8 pairs x 2 episodes x 50 steps = 1600 env steps: 25 iterations of 64
    assert pace.env_steps == 25 * 64 and pace.upper_s == pace.generation_s > 0


def test_a_rerun_uses_its_own_runs_pace_and_skips_finished_runs(tmp_path):
    store = train(tmp_path / "runs" / "vanilla_s0", ES)
    rows = store.read_metrics()
    pace = measured_pace(build_config(ES), [store])
    assert pace.source == "measured"
    later = sorted(float(r["gen_time_s"]) for r in rows[1:])
    assert later[0] <= pace.generation_s <= later[-1]
    cfg = build_config({**ES, "generations": ES["generations"] + 2})
    plan = {"vanilla_s0": ("reuse", cfg), "vanilla_s1": ("new", cfg)}
    est = benchmark_estimate(plan, tmp_path / "runs", lambda name: name.rsplit("_", 1)[0])
    e = est["vanilla"]
    assert e["runs"] == 2 and e["generations"] == 2 + cfg.generations and e["pace"].source == "measured"
    done = benchmark_estimate({"vanilla_s0": ("reuse", build_config(ES))}, tmp_path / "runs",
                              lambda name: "vanilla")
    assert done["vanilla"]["runs"] == 0 and done["vanilla"]["seconds"] == 0.0


def test_the_printed_lines():
    est = {"vanilla": {"runs": 2, "generations": 10, "seconds": 6.0, "upper_seconds": 30.0,
                       "pace": Pace(1.0, 0.5, 2.9, 31_000, "timed")},
           "ppo": {"runs": 2, "generations": 10, "seconds": 1300.0, "upper_seconds": 1300.0,
                   "pace": Pace(3.0, 129.7, 129.7, 32_768, "timed")},
           "cmaes": {"runs": 0, "generations": 0, "seconds": 0.0, "upper_seconds": 0.0, "pace": None}}
    lines = describe(est)
    assert lines[0] == ("vanilla: 2 runs, 10 generations at 0.50 s each (~31,000 env steps, timed just now) "
                        "-> ~6 s (up to 30 s if every episode runs to its time limit)")
    assert lines[1].startswith("ppo: 2 runs, 10 generations at 129.70 s each (~32,768 env steps")
    assert lines[2] == "cmaes: nothing left to run"
    assert lines[3] == "total ~22 min; ppo 100% of it"  # 1306 s, PPO 99.5%
    assert [duration(s) for s in (45, 720, 12_240)] == ["45 s", "12 min", "3.4 h"]


def test_a_benchmark_prints_its_estimate_first(tmp_path):
    from shaped_es.benchmark.runner import run_benchmark
    from shaped_es.benchmark.spec import BenchmarkSpec

    said = []
    spec = BenchmarkSpec(env="CartPole-v1", methods=("vanilla",), seeds=(0,), generations=2,
                         overrides={"executor": "inline", "es.pairs": 4, "rollout.test_episodes": 2,
                                    "tensorboard": False})
    run_benchmark(spec, tmp_path / "b", log=said.append)
    assert said[0].startswith("[benchmark] estimate: vanilla: 1 run, 2 generations at ")
    assert said[1].startswith("[benchmark] estimate: total ~") and said[2].startswith("[benchmark] vanilla_s0: new")
    assert [p.name for p in (tmp_path / "b" / "runs").iterdir()] == ["vanilla_s0"]  # the probe ran elsewhere
    assert len(RunStore(tmp_path / "b" / "runs" / "vanilla_s0").read_metrics()) == 2


def test_estimate_only_writes_nothing(tmp_path):
    from shaped_es.benchmark.runner import run_benchmark
    from shaped_es.benchmark.spec import BenchmarkSpec

    said = []
    spec = BenchmarkSpec(env="CartPole-v1", methods=("vanilla", "cmaes"), seeds=(0, 1), generations=3,
                         overrides={"executor": "inline", "es.pairs": 4, "rollout.test_episodes": 2})
    res = run_benchmark(spec, tmp_path / "b", log=said.append, estimate_only=True)
    assert set(res["estimate_s"]) == {"vanilla", "cmaes"} and all(v > 0 for v in res["estimate_s"].values())
    assert len(said) == 3 and said[0].startswith("[benchmark] estimate: vanilla: 2 runs, 6 generations at ")
    assert said[1].startswith("[benchmark] estimate: cmaes: 2 runs")
    assert said[2].startswith("[benchmark] estimate: total")
    assert not (tmp_path / "b").exists()


def test_estimate_only_needs_no_out(tmp_path, monkeypatch, capsys):
    """``benchmark --estimate-only`` writes nothing, so it asks for no ``--out``; without it, every run is
    still to do. A real benchmark without ``--out`` is one line, exit 2."""
    from shaped_es.cli.commands import main

    monkeypatch.chdir(tmp_path)
    args = ["benchmark", "--env", "CartPole-v1", "--methods", "vanilla", "--seeds", "2", "--generations", "3",
            "--executor", "inline", "--set", "es.pairs=4", "--set", "rollout.test_episodes=2"]
    assert main([*args, "--estimate-only"]) == 0
    out, err = capsys.readouterr()
    assert set(json.loads(out)["estimate_s"]) == {"vanilla"}
    assert "estimate: vanilla: 2 runs, 6 generations" in err
    assert list(tmp_path.iterdir()) == []  # nothing written here
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["shaped-es: error: benchmark needs --out DIR, the benchmark directory (only --estimate-only, "
                   "which writes nothing, runs without it)"]


def test_estimate_only_without_out_as_a_process(tmp_path):
    from helpers import popen_cli

    p = popen_cli("benchmark", "--env", "CartPole-v1", "--methods", "vanilla", "--seeds", "1",
                  "--generations", "2", "--executor", "inline", "--set", "es.pairs=4", "--estimate-only",
                  cwd=tmp_path)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 0, err
    assert "estimate_s" in json.loads(out) and list(tmp_path.iterdir()) == []


def test_a_shaped_probe_keeps_its_run_lines_to_itself(capsys):
    """The timing run's label-probe line is the real runs' to print: the estimate prints none of it."""
    cfg = build_config({"env": "PointVel-v0", "method": "shaped", "executor": "inline", "es": {"pairs": 4},
                        "rollout": {"episodes": 1, "test_episodes": 1}, "tensorboard": False})
    capsys.readouterr()
    assert timed_pace(cfg).generation_s > 0
    assert "labels: frame=" not in capsys.readouterr().err


def test_a_continued_run_is_estimated_at_its_recent_pace():
    """A new user's shaped runs extended from 40 to 80 generations: estimated from all 40 (the probe's and the
    early awake generations' seconds) at 10 min, they took 4.3; their last generations' pace is what goes on."""
    from shaped_es.benchmark.estimate import RECENT

    class Store:  # a run's metrics rows: 30 slow generations, then RECENT fast ones
        def exists(self):
            return True

        def read_metrics(self):
            return [{"gen_time_s": str(2.0 if g < 30 else 0.5), "gen_env_steps": "100", "rollout_time_s": "0.1"}
                    for g in range(30 + RECENT)]

    pace = measured_pace(build_config(ES), [Store()])
    assert pace.generation_s == pytest.approx(0.5)
