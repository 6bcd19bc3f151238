"""summary.json and report.md from hand-made run directories with known metrics."""

import json

import numpy as np
import pytest

from shaped_es.benchmark.markdown import write_report
from shaped_es.benchmark.grouping import group_runs
from shaped_es.benchmark.summary import summarize
from shaped_es.config import build_config
from shaped_es.rundir.store import RunStore, StoreError


def make_run(root, method, seed, tests, wall=1.0, extra=None, env="CartPole-v1"):
    """A run whose generation g has test reward tests[g] (None: not evaluated), wall time (g+1)*wall."""
    store = RunStore(root)
    store.create(build_config({"env": env, "method": method, "seed": seed}))
    for g, t in enumerate(tests):
        row = {"generation": g, "env_steps": 100 * (g + 1), "wall_time_s": wall * (g + 1),
               "cpu_time_s": 2 * wall * (g + 1), "train_reward_mean": 0.0, "train_reward_max": 0.0,
               "train_reward_min": 0.0, "test_reward_mean": t, "test_reward_std": 0.0,
               "test_reward_best_so_far": None, "gen_time_s": wall, "rollout_time_s": wall / 2}
        row.update({k: v[g] for k, v in (extra or {}).items()})
        store.append_metrics(row)
    return root


@pytest.fixture
def runs(tmp_path):
    dirs = [
        make_run(tmp_path / "a0", "vanilla", 0, [1.0, 2.0, 4.0]),
        make_run(tmp_path / "a1", "vanilla", 1, [1.0, None, 6.0]),
        make_run(tmp_path / "b0", "cmaes", 0, [0.0, 1.0, 2.0], wall=2.0),
        make_run(tmp_path / "b1", "cmaes", 1, [0.0, 1.0, 2.0], wall=2.0),
        make_run(tmp_path / "s0", "shaped", 0, [5.0, 6.0, 7.0],
                 extra={"mphi_train_loss": [1.0, 0.5, 0.25], "mphi_test_loss": [2.0, 1.0, 0.5],
                        "mphi_iterations": [500, 1000, 1500], "time_mphi_s": [0.1, 0.1, 0.1]}),
    ]
    return dirs


def test_group_runs_by_config_method(runs, tmp_path):
    groups, configs = group_runs(runs)
    assert list(groups) == ["vanilla", "cmaes", "shaped"]
    assert [d.name for d in groups["vanilla"]] == ["a0", "a1"]
    assert configs["cmaes"].method == "cmaes"
    (tmp_path / "empty").mkdir()
    with pytest.raises(StoreError):
        group_runs([tmp_path / "empty"])


def test_summary_values(runs):
    from shaped_es.benchmark.summary import load_runs

    groups, _ = group_runs(runs)
    s = summarize({k: load_runs(v) for k, v in groups.items()})
    van, cma, ours = s["methods"]["vanilla"], s["methods"]["cmaes"], s["methods"]["shaped"]
    assert van["final_test_reward_mean"] == 5.0
    half = 12.706204736174698 * np.std([4.0, 6.0], ddof=1) / np.sqrt(2)
    assert van["final_test_reward_ci"] == pytest.approx([5.0 - half, 5.0 + half])
    assert cma["final_test_reward_ci"] == [2.0, 2.0]  # identical seeds: zero width
    assert ours["final_test_reward_ci"] is None  # one seed: no interval
    assert van["final_test_reward_iqm"] == 5.0 and 4.0 <= van["final_test_reward_iqm_ci"][0] <= 5.0
    assert cma["final_test_reward_iqm_ci"] == [2.0, 2.0] and ours["final_test_reward_iqm_ci"] is None
    # the late reward: each seed's mean over its last 10 evaluations (here all of them; a missing one skipped)
    assert van["late_test_reward_per_seed"] == [pytest.approx(7 / 3), 3.5] and ours["late_test_reward_iqm"] == 6.0
    # no config (no env): the best baseline's (not 'shaped') final mean = vanilla's 5.0
    assert s["threshold"] == {"value": 5.0, "method": "vanilla", "reference": "shaped",
                              "source": "best baseline's final mean test reward"}
    assert s["budget_generations"] == 3  # the longest run
    assert ours["success_rate"] == 1.0 and ours["to_threshold"]["generations"]["per_seed"] == [1.0]
    assert van["successes"] == 1 and van["success_rate"] == 0.5  # seed 1 jumps to 6 at gen 3
    tt = van["to_threshold"]
    assert tt["reached"] == [False, True]
    assert tt["generations"] == {"mean": 3.5, "median": 3.5, "per_seed": [4.0, 3.0]}  # seed 0 censored: 3 + 1
    assert tt["wall_time_s"]["per_seed"] == [3.0, 3.0] and tt["env_steps"]["per_seed"] == [300.0, 300.0]
    assert cma["success_rate"] == 0.0 and cma["to_threshold"]["generations"]["median"] == 4.0
    assert cma["to_threshold"]["wall_time_s"]["mean"] == 6.0  # censored at the whole run's wall time
    assert cma["wall_time_s"] == 6.0 and cma["cpu_time_s"] == 12.0 and cma["env_steps"] == 300.0
    assert ours["time_split_s"] == pytest.approx({"gen_time_s": 3.0, "rollout_time_s": 1.5, "time_mphi_s": 0.3})
    assert ours["final_mphi_test_loss"] == 0.5
    poi = s["probability_of_improvement"]
    assert poi["vanilla"]["cmaes"]["p"] == 1.0 and poi["vanilla"]["cmaes"]["ci"] == [1.0, 1.0]
    assert poi["cmaes"]["vanilla"]["p"] == 0.0 and poi["shaped"]["vanilla"]["p"] == 1.0
    assert poi["shaped"]["vanilla"]["ci"] is None  # one shaped seed: no interval
    assert set(poi["shaped"]) == {"vanilla", "cmaes"}
    json.dumps(s, allow_nan=False)  # NaN-free


def test_threshold_and_budget(runs):
    from shaped_es.benchmark.summary import load_runs

    groups, _ = group_runs(runs)
    metrics = {k: load_runs(v) for k, v in groups.items()}
    s = summarize(metrics, threshold=2.0, budget=10)
    assert s["threshold"] == {"value": 2.0, "source": "--threshold"}
    van, cma = s["methods"]["vanilla"], s["methods"]["cmaes"]
    assert van["to_threshold"]["generations"]["per_seed"] == [2.0, 3.0]  # seed 1 not evaluated at gen 2
    assert cma["successes"] == 2 and cma["to_threshold"]["env_steps"]["mean"] == 300.0
    s = summarize(metrics, threshold=6.5, budget=10)
    # each run is censored at its own generations (3) + 1, not at the budget's: it never ran 10
    assert s["budget_generations"] == 10
    assert s["methods"]["vanilla"]["to_threshold"]["generations"] == {"mean": 4.0, "median": 4.0,
                                                                       "per_seed": [4.0, 4.0]}
    assert s["methods"]["shaped"]["to_threshold"]["generations"]["per_seed"] == [3.0]


@pytest.mark.parametrize("env, kwargs, value", [
    ("CarNav-v0", {}, 200.0), ("shaped_es:CarNav-v0", {"waypoint_spacing": 15.0}, 200.0),
    ("UR5Reach-v0", {"preset": "default"}, 40.0),
    ("CarNav-v0", {"preset": "paper"}, 5.0), ("UR5Reach-v0", {"max_steps": 400}, 5.0),  # rescaled: fallback
])
def test_env_default_thresholds(runs, env, kwargs, value):
    from shaped_es.benchmark.summary import load_runs

    groups, _ = group_runs(runs)
    cfg = build_config({"env": env, "method": "vanilla", "env_kwargs": kwargs})
    s = summarize({k: load_runs(v) for k, v in groups.items()}, config=cfg)
    assert s["threshold"]["value"] == value
    assert ("default" in s["threshold"]["source"]) == (value != 5.0)


@pytest.mark.parametrize("env, value, source", [
    ("thr_user_env:Hover-v0", 8.5, "thr_user_env:Hover-v0 reward_threshold (registered with its Gymnasium spec)"),
    ("CartPole-v1", 475.0, "CartPole-v1 reward_threshold (registered with its Gymnasium spec)"),
    ("thr_user_env:Bare-v0", 5.0, "best baseline's final mean test reward"),  # registered without one
    ("Pendulum-v1", 5.0, "best baseline's final mean test reward"),
    ("not_a_module_here:Hover-v0", 5.0, "best baseline's final mean test reward"),  # cannot be looked up
])
def test_any_env_registered_with_a_reward_threshold_uses_it(runs, tmp_path, monkeypatch, env, value, source):
    # a user's env registered with reward_threshold=8.5 got the best baseline's final mean instead
    from shaped_es.benchmark.summary import load_runs

    (tmp_path / "thr_user_env.py").write_text(
        "import gymnasium as gym\n"
        "gym.register('Hover-v0', entry_point='gymnasium.envs.classic_control:PendulumEnv', reward_threshold=8.5)\n"
        "gym.register('Bare-v0', entry_point='gymnasium.envs.classic_control:PendulumEnv')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    groups, _ = group_runs(runs)
    cfg = build_config({"env": env, "method": "vanilla", "env_kwargs": {"g": 9.0}})
    s = summarize({k: load_runs(v) for k, v in groups.items()}, config=cfg)
    assert s["threshold"]["value"] == value and s["threshold"]["source"] == source


def test_summary_cut_to_generations(runs):
    from shaped_es.benchmark.summary import load_runs

    groups, _ = group_runs(runs)
    s = summarize({k: load_runs(v, generations=2) for k, v in groups.items()})
    assert s["methods"]["vanilla"]["final_test_reward_mean"] == 1.5  # last finite of [1, 2] and [1, -]
    assert s["methods"]["vanilla"]["generations"] == 2


def test_report_files(runs, tmp_path):
    groups, configs = group_runs(runs)
    out = write_report(tmp_path / "rep" / "report.md", groups, configs, threshold=2.0)
    md = (tmp_path / "rep" / "report.md").read_text()
    assert (tmp_path / "rep" / "figures" / "fig4_test_reward.png").stat().st_size > 10_000
    assert out["fig5"] and (tmp_path / "rep" / "figures" / "fig5_mphi_loss.png").is_file()
    assert out["profile"] and (tmp_path / "rep" / "figures" / "profile_final_reward.png").stat().st_size > 10_000
    assert "![Fig. 5](figures/fig5_mphi_loss.png)" in md
    assert "![Performance profile](figures/profile_final_reward.png)" in md
    assert "| vanilla | 2 | 5.00 [" in md  # IQM and its interval
    assert "5.00 ± " in md
    assert "| vanilla | 2 | 2/2 (100%) | 2.5 / 2.5 |" in md  # success, generations to 2.0
    assert "| vanilla | – | 1.00 [1.00, 1.00] | 0.00 – |" in md  # P(row > column); 1 shaped seed: no CI
    assert "| cmaes | 0.00 [0.00, 0.00] | – |" in md
    assert "no pair does" in md  # 2 seeds a side: the interval is [1, 1] but Mann-Whitney p = 0.22
    assert "test reward >= 2.00 (--threshold)" in md and "3 + 1 = 4 for a run of 3 generations" in md
    assert "time_mphi_s" in md
    # the verdict the benchmark prints as it ends, on the page too (a new user's crane looked for it there)
    verdict = md.split("## Verdict in brief")[1].split("## ")[0]
    assert "- cmaes vs vanilla: " in verdict and "- shaped vs vanilla: " in verdict
    summary = json.loads((tmp_path / "rep" / "summary.json").read_text())
    assert set(summary["methods"]) == {"vanilla", "cmaes", "shaped"}
    assert summary["figures"]["fig4"] == "figures/fig4_test_reward.png"
    assert summary["figures"]["profile"] == "figures/profile_final_reward.png"


def test_report_without_mphi_columns_notes_it(runs, tmp_path):
    groups, configs = group_runs(runs[:4])
    out = write_report(tmp_path / "rep" / "report.md", groups, configs)
    assert out["fig5"] is None
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "_Not drawn: no run logs `mphi_train_loss`" in md
    assert not (tmp_path / "rep" / "figures" / "fig5_mphi_loss.png").exists()


def test_a_redrawn_page_drops_only_its_own_figure_it_no_longer_draws(runs, tmp_path):
    groups, configs = group_runs(runs)
    fig5 = tmp_path / "rep" / "figures" / "fig5_mphi_loss.png"
    write_report(tmp_path / "rep" / "report.md", groups, configs)
    mine = tmp_path / "rep" / "figures" / "my_notes.png"
    mine.write_bytes(b"a user's own file")
    assert fig5.is_file()
    groups, configs = group_runs(runs[:4])  # no run logs M_phi's losses: Fig. 5 is not drawn
    write_report(tmp_path / "rep" / "report.md", groups, configs)
    assert not fig5.exists() and mine.read_bytes() == b"a user's own file"
    assert (tmp_path / "rep" / "figures" / "fig4_test_reward.png").is_file()


def test_report_says_which_method_beats_which(tmp_path):
    """6 seeds a side, every vanilla seed above every cmaes seed: P = 1 [1, 1], exact Mann-Whitney
    p = 2 / C(12, 6) = 0.0022 -> 'vanilla > cmaes'; the reverse and identical methods are not verdicts."""
    env = "Pendulum-v1"  # no registered reward_threshold: the best baseline's final mean is the threshold
    dirs = [make_run(tmp_path / f"v{s}", "vanilla", s, [0.0, 10.0 + s], env=env) for s in range(6)]
    dirs += [make_run(tmp_path / f"c{s}", "cmaes", s, [0.0, float(s)], env=env) for s in range(6)]
    dirs += [make_run(tmp_path / f"g{s}", "guided", s, [0.0, float(s)], env=env) for s in range(6)]
    groups, configs = group_runs(dirs)
    write_report(tmp_path / "rep" / "report.md", groups, configs)
    md = (tmp_path / "rep" / "report.md").read_text()
    s = json.loads((tmp_path / "rep" / "summary.json").read_text())
    poi = s["probability_of_improvement"]
    assert poi["vanilla"]["cmaes"]["p_value"] == pytest.approx(2 / 924)
    assert poi["cmaes"]["guided"]["p"] == 0.5 and poi["cmaes"]["guided"]["p_value"] == pytest.approx(1.0)
    assert "vanilla > cmaes (P = 1.00, Mann-Whitney p = 0.002)" in md
    assert "vanilla > guided" in md and "cmaes > guided" not in md and "cmaes > vanilla" not in md
    # threshold = best baseline final mean (no 'shaped'): vanilla's 12.5; 3 of its 6 seeds reach it
    assert s["threshold"]["value"] == 12.5 and s["methods"]["vanilla"]["successes"] == 3
    assert s["methods"]["cmaes"]["to_threshold"]["generations"]["per_seed"] == [3.0] * 6  # budget 2 + 1
    # cmaes and guided: no seed of either reached it; their ratio of budgets is not a tie (a new user's drone)
    assert ("| cmaes / guided | n/a: no seed of either reached it (every seed censored; more --generations, or a "
            "--threshold within the runs' reach, would tell them apart) |") in md
    assert "| vanilla / cmaes | 0." in md  # one of them solved: a ratio


def test_settings_show_what_each_method_uses_as_plain_values(runs, tmp_path):
    from shaped_es.benchmark.grouping import method_settings

    def settings(method, **over):
        return method_settings(build_config({"env": "CarNav-v0", "method": method, "es": {"sigma": 0.1},
                                             "env_kwargs": {"preset": "paper"}, **over}))

    van, shaped, ppo = settings("vanilla"), settings("shaped"), settings("ppo", ppo={"n_steps": 256})
    assert {"pairs", "sigma", "lr", "executor", "workers"} <= set(van) and not {"alpha", "eta"} & set(van)
    assert shaped["alpha"] == 0.9 and shaped["eta"] == 0.01 and shaped["sigma"] == 0.1
    assert not {"sigma", "lr", "alpha", "eta", "workers"} & set(ppo) and ppo["executor"] == "none (one process)"
    assert ppo["other non-defaults"] == "ppo.n_steps=256" and van["other non-defaults"] == "none"
    inline = settings("vanilla", executor="inline")  # the rollouts in the trainer's process: no workers to name
    assert inline["executor"] == "inline" and "workers" not in inline
    # an es field a method never reads is no "non-default" of it
    assert settings("ppo", es={"optimizer": "sgd"})["other non-defaults"] == "none"
    assert settings("vanilla", es={"optimizer": "sgd"})["other non-defaults"] == "es.optimizer=sgd"
    groups, configs = group_runs(runs)
    write_report(tmp_path / "rep" / "report.md", groups, configs)
    md = (tmp_path / "rep" / "report.md").read_text()
    table = md[md.index("## Settings"):md.index("## Runs")]
    assert "| vanilla | env CartPole-v1; pairs 32; sigma 0.05; lr 0.03; episodes 2; test episodes 15; " \
           "tested policy mean; executor process; workers all cores; other non-defaults none |" in table
    assert settings("vanilla", rollout={"test_policy": "best"})["tested policy"] == "best"
    assert "tested policy" not in ppo  # PPO tests its own policy
    assert "alpha 0.9; eta 0.01" in table and '"' not in table and "`" not in table


def test_the_late_reward_is_the_mean_of_the_last_ten_evaluations():
    from shaped_es.benchmark.summary import LATE_EVALUATIONS, late_rewards

    tests = np.arange(15, dtype=float)  # 0..14
    tests[13] = np.nan  # not evaluated there
    got = late_rewards([{"test_reward_mean": tests}, {"test_reward_mean": np.full(3, np.nan)}])
    assert LATE_EVALUATIONS == 10 and got[0] == pytest.approx(np.mean([4, 5, 6, 7, 8, 9, 10, 11, 12, 14]))
    assert np.isnan(got[1])
