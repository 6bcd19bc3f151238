"""The whole benchmark on a tiny budget (CartPole, vanilla/cmaes/ppo, 2 seeds, 2 generations), its rerun
semantics (skip finished, resume unfinished, refuse a changed config) and the ablation switches."""

import argparse
import json
from dataclasses import dataclass

import gymnasium as gym
import numpy as np
import pytest

from shaped_es.benchmark.cli_commands import add_benchmark_parser
from shaped_es.benchmark.spec import BenchmarkSpec, run_configs
from shaped_es.cli.commands import add_report_parser
from shaped_es.config import ConfigError
from shaped_es.rundir.store import StoreError


def tiny(seeds=2, generations=2):
    return ["--env", "CartPole-v1", "--seeds", seeds, "--generations", generations, "--executor", "inline",
            "--set", "es.pairs=4", "--set", "rollout.max_steps=100", "--set", "rollout.test_episodes=3",
            "--set", "policy.hidden=[8]", "--set", "tensorboard=false", "--quiet",
            # PPO with a small rollout: SB3's 2048 steps x 10 epochs would dominate a tiny benchmark
            "--set", "ppo.n_steps=256", "--set", "ppo.n_epochs=4", "--no-estimate"]


TINY = tiny()
KEYS = {"final_test_reward_mean", "final_test_reward_ci", "final_test_reward_iqm", "final_test_reward_iqm_ci",
        "success_rate", "successes", "to_threshold", "wall_time_s", "cpu_time_s", "env_steps"}


def _parse(command, *argv):
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="command")
    add_benchmark_parser(sub)
    add_report_parser(sub)
    return p.parse_args([command, *map(str, argv)])


def _cli(command, *argv):
    a = _parse(command, *argv)
    return a.fn(a)


def _metrics(out):
    return {d.name: (d / "metrics.csv").read_text() for d in sorted((out / "runs").iterdir())}


@pytest.fixture(scope="module")
def bench(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "b"
    assert _cli("benchmark", *TINY, "--methods", "vanilla,cmaes,ppo", "--out", out) == 0
    return out


def test_benchmark_writes_runs_summary_and_report(bench):
    names = sorted(d.name for d in (bench / "runs").iterdir())
    assert names == ["cmaes_s0", "cmaes_s1", "ppo_s0", "ppo_s1", "vanilla_s0", "vanilla_s1"]
    for rows in _metrics(bench).values():
        assert len(rows.strip().splitlines()) == 1 + 2  # header + 2 generations
    s = json.loads((bench / "summary.json").read_text())
    assert list(s["methods"]) == ["vanilla", "cmaes", "ppo"]
    for m in s["methods"].values():
        assert KEYS <= set(m) and m["seeds"] == 2
        assert m["final_test_reward_mean"] >= 1 and m["cpu_time_s"] > 0 and m["env_steps"] > 0
        lo, hi = m["final_test_reward_ci"]
        assert lo <= m["final_test_reward_mean"] <= hi
        assert set(m["to_threshold"]) == {"reached", "budgets", "generations", "wall_time_s", "cpu_time_s",
                                          "env_steps"}
        lo, hi = m["final_test_reward_iqm_ci"]
        assert lo <= m["final_test_reward_iqm"] <= hi
    # CartPole-v1's Gymnasium spec has reward_threshold 475: the threshold, not the best final mean
    assert s["threshold"] == {"value": 475.0, "source": "CartPole-v1 reward_threshold (registered with its "
                                                        "Gymnasium spec)"}
    assert s["budget_generations"] == 2
    assert set(s["probability_of_improvement"]["ppo"]) == {"vanilla", "cmaes"}
    # CartPole's 475 is reached by nobody in 2 generations: every ratio of censored means is 3 / 3
    ratio = s["ratios_to_threshold"]["vanilla"]["cmaes"]["generations"]
    assert ratio["ratio"] == 1.0 and set(s["ratios_to_threshold"]["ppo"]) == {"vanilla", "cmaes"}
    assert {v["status"] for v in s["this_invocation"].values()} == {"new"}
    assert s["benchmark"]["seeds"] == [0, 1] and s["settings"]["ppo"]["pairs"] == 4
    md = (bench / "report.md").read_text()
    assert "![Fig. 4](figures/fig4_test_reward.png)" in md and "_Not drawn" in md
    assert all(f"| {m} | 2 |" in md for m in ("vanilla", "cmaes", "ppo"))
    # each pair once, in order; nobody reached 475: a ratio of two budgets is no tie, and the cell says so
    assert "| vanilla / cmaes | n/a: no seed of either reached it" in md and "| cmaes / vanilla |" not in md
    assert (bench / "figures" / "fig4_test_reward.png").stat().st_size > 10_000
    assert (bench / "figures" / "profile_final_reward.png").stat().st_size > 10_000
    assert (bench / "benchmark.yaml").is_file()


def test_rerun_skips_finished_runs(bench, capsys):
    before = _metrics(bench)
    assert _cli("benchmark", *TINY, "--methods", "vanilla,cmaes,ppo", "--threshold", 1e6, "--out", bench) == 0
    s = json.loads((bench / "summary.json").read_text())
    assert {v["status"] for v in s["this_invocation"].values()} == {"skipped"}
    assert _metrics(bench) == before
    printed = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert printed["report"].endswith("report.md") and printed["profile"].endswith("profile_final_reward.png")
    # --threshold reaches the summary: nobody reaches 1e6, every seed censored at 2 + 1 generations
    assert s["threshold"] == {"value": 1e6, "source": "--threshold"}
    for m in s["methods"].values():
        assert m["success_rate"] == 0.0 and m["to_threshold"]["generations"]["per_seed"] == [3.0, 3.0]
    assert "test reward >= 1000000.00 (--threshold)" in (bench / "report.md").read_text()


def test_defaults_and_threshold_flags():
    a = _parse("benchmark", "--env", "CarNav-v0", "--out", "x")
    assert a.seeds == 10 and a.threshold is None
    assert _parse("report", "x", "--threshold", "40").threshold == 40.0
    with pytest.raises(ConfigError, match="--threshold"):
        _cli("report", "x", "--threshold", "nan")


def test_report_command_groups_runs_by_method(bench, tmp_path, capsys):
    assert _cli("report", bench / "runs" / "vanilla_s0", bench / "runs" / "ppo_s1", bench / "runs" / "vanilla_s1",
                "--out", tmp_path / "r" / "report.md") == 0
    s = json.loads((tmp_path / "r" / "summary.json").read_text())
    assert {k: v["seeds"] for k, v in s["methods"].items()} == {"vanilla": 2, "ppo": 1}
    assert _cli("report", bench, "--out", tmp_path / "fig.png") == 0  # a benchmark dir: all its runs
    assert (tmp_path / "fig.png").is_file() and not (tmp_path / "fig_mphi.png").exists()
    assert (tmp_path / "fig_profile.png").stat().st_size > 10_000
    with pytest.raises(ConfigError, match=".md"):
        _cli("report", bench, "--out", tmp_path / "fig.txt")


def test_report_page_never_overwrites_another_reports_files(bench, tmp_path):
    assert _cli("report", bench / "runs" / "vanilla_s0", "--out", tmp_path / "a.md") == 0
    before = (tmp_path / "summary.json").read_bytes()
    with pytest.raises(ConfigError, match=r"would overwrite .*summary.json.*no report b.md wrote"):
        _cli("report", bench / "runs" / "ppo_s1", "--out", tmp_path / "b.md")
    assert (tmp_path / "summary.json").read_bytes() == before and not (tmp_path / "b.md").exists()
    assert _cli("report", bench / "runs" / "vanilla_s0", "--out", tmp_path / "a.md") == 0  # redraw: fine


def test_unfinished_runs_resume_and_changed_configs_are_refused(tmp_path):
    out = tmp_path / "b"
    assert _cli("benchmark", *tiny(seeds=1, generations=1), "--methods", "vanilla,ppo", "--out", out) == 0
    longer = [*tiny(seeds=1, generations=2), "--methods", "vanilla,ppo"]
    assert _cli("benchmark", *longer, "--out", out) == 0
    s = json.loads((out / "summary.json").read_text())
    assert {v["status"] for v in s["this_invocation"].values()} == {"resumed"}
    for rows in _metrics(out).values():
        assert [r.split(",")[0] for r in rows.strip().splitlines()[1:]] == ["0", "1"]
    with pytest.raises(StoreError, match="different config.*es.sigma"):
        _cli("benchmark", *longer, "--set", "es.sigma=0.3", "--out", out)


@dataclass(frozen=True)
class _Cfg:
    waypoint_spacing: float = 1.5


class SpacingEnv(gym.Env):
    """Stand-in for CarNav-v0: resolves its waypoint spacing into a config object."""

    observation_space = gym.spaces.Box(-1, 1, (2,), np.float32)
    action_space = gym.spaces.Box(-1, 1, (1,), np.float32)

    def __init__(self, preset="default", waypoint_spacing=None):
        self.config = _Cfg(waypoint_spacing or (3.0 if preset == "coarse" else 1.5))


gym.register("Spacing-v0", entry_point=SpacingEnv)


def test_ablation_switches_reach_the_configs():
    spec = dict(env="Spacing-v0", methods=("vanilla", "guided"), seeds=(0, 3), generations=5)
    cfgs = run_configs(BenchmarkSpec(**spec, sparse_waypoints=True, alpha=0.3, eta=0.05))
    assert list(cfgs) == ["vanilla_s0", "guided_s0", "vanilla_s3", "guided_s3"]
    for c in cfgs.values():
        assert c.env_kwargs == {"waypoint_spacing": 15.0} and c.es.alpha == 0.3 and c.shaping.eta == 0.05
        assert c.generations == 5
    preset = run_configs(BenchmarkSpec(**spec, sparse_waypoints=True, overrides={"env_kwargs.preset": "coarse"}))
    assert preset["vanilla_s0"].env_kwargs == {"preset": "coarse", "waypoint_spacing": 30.0}
    given = run_configs(BenchmarkSpec(**spec, sparse_waypoints=True, base={"env_kwargs": {"waypoint_spacing": 2}}))
    assert given["guided_s3"].env_kwargs == {"waypoint_spacing": 20.0}


def test_bad_input_is_one_clear_error(tmp_path):
    with pytest.raises(ConfigError, match="--sparse-waypoints: env CartPole-v1"):
        _cli("benchmark", *TINY, "--methods", "vanilla", "--sparse-waypoints", "--out", tmp_path / "x")
    with pytest.raises(ConfigError, match="--methods: unknown"):
        _cli("benchmark", *TINY, "--methods", "vanilla,sgd", "--out", tmp_path / "x")
    with pytest.raises(ConfigError, match="es.pairs"):
        _cli("benchmark", *TINY, "--methods", "vanilla", "--set", "es.pairs=0", "--out", tmp_path / "x")
    assert not (tmp_path / "x").exists()  # nothing written before the input is known good


def test_grid_sweeps_every_combination_as_a_variant():
    from shaped_es.benchmark.cli_commands import grid_variants

    v = grid_variants(["vanilla"], ["es.sigma=0.05,0.1", "es.lr=0.01,0.02"])
    assert list(v) == ["vanilla-sigma0.05-lr0.01", "vanilla-sigma0.05-lr0.02", "vanilla-sigma0.1-lr0.01",
                       "vanilla-sigma0.1-lr0.02"]
    assert v["vanilla-sigma0.1-lr0.02"] == {"method": "vanilla", "es.sigma": 0.1, "es.lr": 0.02}
    drawn = grid_variants(["vanilla"], ["es.sigma=0.05,0.1", "es.lr=0.01,0.02"], sample=2, seed=3)
    assert len(drawn) == 2 and set(drawn) <= set(v)
    assert drawn == grid_variants(["vanilla"], ["es.sigma=0.05,0.1", "es.lr=0.01,0.02"], sample=2, seed=3)
    for bad in (["es.sigma"], ["es.sigma=0.1", "es.sigma=0.2"]):
        with pytest.raises(ConfigError):
            grid_variants(["vanilla"], bad)
    with pytest.raises(ConfigError, match="--sample"):
        grid_variants(["vanilla"], ["es.sigma=0.05,0.1"], sample=5)


def test_a_sweep_is_one_benchmark(tmp_path):
    out = tmp_path / "sweep"
    assert _cli("benchmark", *tiny(seeds=1, generations=1), "--methods", "vanilla", "--grid",
                "es.sigma=0.05,0.1", "--out", out) == 0
    assert sorted(d.name for d in (out / "runs").iterdir()) == ["vanilla-sigma0.05_s0", "vanilla-sigma0.1_s0"]
    s = json.loads((out / "summary.json").read_text())
    assert list(s["methods"]) == ["vanilla-sigma0.05", "vanilla-sigma0.1"]
    assert "sigma: 0.05" in (out / "runs" / "vanilla-sigma0.05_s0" / "config.yaml").read_text()


def test_a_runs_line_says_what_its_labels_did(tmp_path):
    """A new user's benchmark printed nothing per run about candidates never accepted (only the report did)."""
    from types import SimpleNamespace

    from shaped_es.benchmark.runner import _outcome

    def run(name, accepted):
        root = tmp_path / name
        root.mkdir()
        rows = ["generation,test_reward_mean,shaping_awake,candidate_accepted,candidate_gain"]
        rows += [f"{g},{g + 0.5},1,{a},{-1.0 if a == 0 else 1.0}" for g, a in enumerate(accepted)]
        (root / "metrics.csv").write_text("\n".join(rows) + "\n")
        return root

    shaped = SimpleNamespace(method="shaped", env="CartPole-v1", env_kwargs={})  # its registered threshold: 475
    assert _outcome(shaped, run("never", [0, 0, 0])) == (", last test reward 2.50, 475 not reached; no candidate "
                                                         "accepted in 3 judged generations: vanilla's own steps")
    assert _outcome(SimpleNamespace(method="shaped_cmaes", env="CartPole-v1", env_kwargs={}),
                    run("never_cma", [0])).endswith("cmaes's own steps")
    assert _outcome(shaped, run("paid", [0, 1, 0])) == (", last test reward 2.50, 475 not reached; candidates "
                                                        "accepted 1 of 3 judged")
    # the threshold benchmark uses (given, else the env's), where a test reward met it: generations done
    assert _outcome(shaped, tmp_path / "paid", 1.5) == (", last test reward 2.50, 1.5 reached at generation 2; "
                                                        "candidates accepted 1 of 3 judged")
    assert _outcome(SimpleNamespace(method="vanilla"), tmp_path / "missing") == ""
    slept = tmp_path / "slept"  # three generations slept through price the awake ones: about what shaping cost
    slept.mkdir()
    (slept / "metrics.csv").write_text(
        "generation,test_reward_mean,shaping_awake,candidate_accepted,candidate_gain,gen_time_s,wall_time_s\n"
        "0,1.0,1,0,-1.0,3.0,9.0\n1,1.5,1,0,-1.0,3.0,12.0\n2,2.0,0,,,1.0,13.0\n3,2.0,0,,,1.0,14.0\n"
        "4,2.5,0,,,1.0,15.0\n")
    assert _outcome(shaped, slept).endswith("no candidate accepted in 2 judged generations: vanilla's own steps "
                                            "(shaping about 4 s of 15 s)")  # no probe file: its 0 s
    checked = tmp_path / "checked"  # check_episodes: a winner the check did not bear out
    checked.mkdir()
    (checked / "metrics.csv").write_text("generation,test_reward_mean,shaping_awake,candidate_accepted,"
                                         "candidate_gain,check_env_steps\n0,1.0,1,1,1.0,60\n1,2.5,1,0,1.0,60\n")
    assert _outcome(shaped, checked) == (", last test reward 2.50, 475 not reached; candidates accepted 1 of 2 judged "
                                         "(1 more won and lost the check)")


def test_a_runs_line_says_whose_candidates_won(tmp_path):
    """A new user's benchmark (a boat, three arms) could not tell per run which rival's candidates were accepted:
    only train's closing line said it, and a benchmark prints none."""
    from types import SimpleNamespace

    from shaped_es.benchmark.runner import _outcome

    root = tmp_path / "rivals"
    root.mkdir()
    # rival codes: 0 the run's own labels, 3 the shooting labels', 5 the probe's candidate, 8 the held-goal one
    (root / "metrics.csv").write_text(
        "generation,test_reward_mean,shaping_awake,candidate_accepted,candidate_gain,candidate_rival,shoot_gain,"
        "shoot_hold_gain\n0,1.0,1,1,1.0,5,,\n1,1.5,1,1,1.0,3,1.0,\n2,2.0,1,0,-1.0,0,-1.0,\n3,2.5,1,1,1.0,8,0.0,1.0\n"
        "4,3.0,1,1,1.0,0,0.0,\n")
    shaped = SimpleNamespace(method="shaped", env="CartPole-v1", env_kwargs={})
    assert _outcome(shaped, root) == (", last test reward 3.00, 475 not reached; candidates accepted 4 of 5 judged "
                                      "(own labels 1, the probe's 1, shooting 1, held-goal shooting 1)")
