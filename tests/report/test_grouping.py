"""``shaped-es report`` keeps runs of different experiments apart: runs of one method on different envs,
or with a different setting of their method, are labelled groups of their own (one warning line names
what differs), never one averaged curve; the seed, the budget and where a run ran do not split a group."""

import json
import warnings

import pytest

from shaped_es.benchmark.grouping import ReportWarning, group_runs
from shaped_es.cli.commands import main
from shaped_es.config import build_config
from shaped_es.rundir.store import RunStore


def test_grouping_names_stay_importable_from_summary():
    """``benchmark/grouping.py`` was part of ``benchmark/summary.py``: its names are still importable there."""
    from shaped_es.benchmark import grouping, summary

    for name in ("ReportWarning", "group_runs", "report_env", "run_settings", "method_settings", "non_defaults",
                 "plain", "uses"):
        assert getattr(summary, name) is getattr(grouping, name), name


def make_run(root, method="shaped", env="CarNav-v0", seed=0, tests=(1.0, 2.0), **over):
    """A run directory with its config.yaml and a metrics.csv of len(tests) generations."""
    store = RunStore(root)
    store.create(build_config({"env": env, "method": method, "seed": seed, **over}))
    for g, t in enumerate(tests):
        store.append_metrics({"generation": g, "env_steps": 100 * (g + 1), "wall_time_s": g + 1.0,
                              "cpu_time_s": g + 1.0, "train_reward_mean": 0.0, "train_reward_max": 0.0,
                              "train_reward_min": 0.0, "test_reward_mean": t, "test_reward_std": 0.0,
                              "test_reward_best_so_far": None, "gen_time_s": 1.0, "rollout_time_s": 0.5})
    return root


def _group(dirs):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        groups, configs = group_runs(dirs)
    return groups, configs, [str(w.message) for w in caught if issubclass(w.category, ReportWarning)]


def test_runs_on_different_envs_are_groups_of_their_own(tmp_path):
    dirs = [make_run(tmp_path / "car0", seed=0), make_run(tmp_path / "ur5", env="UR5Reach-v0"),
            make_run(tmp_path / "car1", env="shaped_es:CarNav-v0", seed=1), make_run(tmp_path / "v", "vanilla")]
    groups, configs, said = _group(dirs)
    assert {k: [d.name for d in v] for k, v in groups.items()} == {
        "shaped (CarNav-v0)": ["car0", "car1"], "shaped (UR5Reach-v0)": ["ur5"], "vanilla": ["v"]}
    assert configs["shaped (UR5Reach-v0)"].env == "UR5Reach-v0"
    assert len(said) == 1 and "'shaped' runs differ in env," in said[0]
    assert "shaped (CarNav-v0) (2 runs); shaped (UR5Reach-v0) (1 run)" in said[0]


def test_a_different_setting_of_the_method_splits_and_warns(tmp_path):
    dirs = [make_run(tmp_path / "a0", seed=0, shaping={"mechanism": "paper"}),
            make_run(tmp_path / "a1", seed=1, shaping={"mechanism": "paper"}),
            make_run(tmp_path / "b0", seed=0, shaping={"mechanism": "candidate", "eta": 0.1})]
    groups, _, said = _group(dirs)
    assert list(groups) == ["shaped (shaping.mechanism=paper, shaping.eta=0.01)",
                            "shaped (shaping.mechanism=candidate, shaping.eta=0.1)"]
    assert len(said) == 1 and "differ in shaping.mechanism, shaping.eta" in said[0]


def test_seed_budget_and_where_it_ran_keep_one_group(tmp_path):
    dirs = [make_run(tmp_path / "a", seed=0, generations=10, executor="inline", tests=(1.0, 2.0, 3.0)),
            make_run(tmp_path / "b", seed=7, generations=50, executor="process", workers=2,
                     shaping={"placement": "workers"}),
            # a field of a section the method does not read (PPO's, for an ES method)
            make_run(tmp_path / "c", seed=3, ppo={"n_steps": 64})]
    groups, _, said = _group(dirs)
    assert list(groups) == ["shaped"] and len(groups["shaped"]) == 3 and said == []


def test_many_differences_keep_labels_short_and_distinct(tmp_path):
    base = {"es": {"sigma": 0.1, "lr": 0.01}, "rollout": {"episodes": 3}}
    dirs = [make_run(tmp_path / "a", "vanilla", **base), make_run(tmp_path / "b", "vanilla"),
            make_run(tmp_path / "c", "vanilla", es={"sigma": 0.1, "lr": 0.01})]
    groups, _, said = _group(dirs)
    assert list(groups) == ["vanilla (es.sigma=0.1, es.lr=0.01, rollout.episodes=3)",
                            "vanilla (es.sigma=0.05, es.lr=0.03, rollout.episodes=2)",
                            "vanilla (es.sigma=0.1, es.lr=0.01, rollout.episodes=2)"]
    dirs.append(make_run(tmp_path / "d", "vanilla", es={"sigma": 0.1, "lr": 0.01, "alpha": 0.5, "pairs": 4}))
    groups, _, said = _group(dirs)
    assert len(groups) == 4 and all(k.startswith("vanilla (es.pairs=") for k in groups)
    assert all("+2 more settings)" in k for k in groups)  # pairs, sigma, then the rest counted
    assert len(said) == 1 and "es.pairs, es.sigma, es.lr, rollout.episodes" in said[0]


def test_report_command_warns_in_one_line_and_reports_the_groups_apart(tmp_path, capsys):
    dirs = [make_run(tmp_path / "car", tests=(210.0, 220.0)), make_run(tmp_path / "ur5", env="UR5Reach-v0",
                                                                      tests=(10.0, 20.0))]
    out = tmp_path / "rep" / "report.md"
    assert main(["report", *map(str, dirs), "--out", str(out)]) == 0
    err = capsys.readouterr().err
    warns = [x for x in err.splitlines() if x.startswith("shaped-es: warning:")]
    assert len(warns) == 1 and "'shaped' runs differ in env" in warns[0]
    summary = json.loads((tmp_path / "rep" / "summary.json").read_text())
    assert set(summary["methods"]) == {"shaped (CarNav-v0)", "shaped (UR5Reach-v0)"}
    assert summary["methods"]["shaped (UR5Reach-v0)"]["final_test_reward_mean"] == 20.0
    # no one env's default success threshold fits both
    assert "default" not in summary["threshold"]["source"]
    md = out.read_text()
    assert "CarNav-v0, UR5Reach-v0" in md and "| shaped (UR5Reach-v0) |" in md


@pytest.mark.parametrize("suffix", [".png"])
def test_report_figure_names_both_envs(tmp_path, capsys, suffix):
    dirs = [make_run(tmp_path / "car"), make_run(tmp_path / "ur5", env="UR5Reach-v0")]
    assert main(["report", *map(str, dirs), "--out", str(tmp_path / f"fig{suffix}")]) == 0
    assert (tmp_path / f"fig{suffix}").stat().st_size > 10_000
    assert "differ in env" in capsys.readouterr().err


def test_a_benchmark_directory_reports_in_its_method_order_with_its_verdict(tmp_path, capsys):
    """``report BENCH``: its runs in benchmark.yaml's method order, then by seed as a number (a new user's report
    of one benchmark, by name, put CMA-ES first: "cmaes / shaped 6.56x"), and the benchmark's verdict lines
    against Vanilla-ES (a one-benchmark report printed none)."""
    from shaped_es.cli.results import expand_run_dirs

    bench = tmp_path / "bench"
    (bench / "runs").mkdir(parents=True)
    (bench / "benchmark.yaml").write_text("env: CarNav-v0\nmethods: [shaped, vanilla, cmaes]\nseeds: [0, 2, 10]\n")
    for method, tests in (("cmaes", (1.0, 2.0)), ("vanilla", (1.0, 3.0)), ("shaped", (5.0, 6.0))):
        for seed in (0, 2, 10):
            make_run(bench / "runs" / f"{method}_s{seed}", method, seed=seed, tests=tests)
    names = [d.name for d in expand_run_dirs([str(bench)])]
    assert names == [f"{m}_s{s}" for m in ("shaped", "vanilla", "cmaes") for s in (0, 2, 10)]
    out = tmp_path / "rep" / "report.md"
    assert main(["report", str(bench), "--out", str(out), "--threshold", "4"]) == 0
    summary = json.loads((tmp_path / "rep" / "summary.json").read_text())
    assert list(summary["methods"]) == ["shaped", "vanilla", "cmaes"]
    verdicts = [ln for ln in capsys.readouterr().err.splitlines() if ln.startswith("[report] ")]
    assert [v.split(":")[0] for v in verdicts] == ["[report] shaped vs vanilla", "[report] cmaes vs vanilla"]
    assert verdicts[0].startswith("[report] shaped vs vanilla: 3/3 vs 0/3 seeds reached 4")
