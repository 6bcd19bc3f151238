"""summary.json and report.md from hand-made run directories with known metrics."""

import json

import numpy as np
import pytest

from shaped_es.benchmark.markdown import write_report
from shaped_es.benchmark.summary import group_runs, summarize
from shaped_es.config import build_config
from shaped_es.store import RunStore, StoreError


def make_run(root, method, seed, tests, wall=1.0, extra=None):
    """A run whose generation g has test reward tests[g] (None: not evaluated), wall time (g+1)*wall."""
    store = RunStore(root)
    store.create(build_config({"env": "CartPole-v1", "method": method, "seed": seed}))
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
    # target: best baseline (not 'shaped') final mean = vanilla's 5.0
    assert s["target"] == {"value": 5.0, "method": "vanilla", "reference": "shaped"}
    assert ours["generations_to_target"] == 1.0 and ours["reached_target"] == "1/1"
    assert van["generations_to_target"] == 3.0 and van["reached_target"] == "1/2"  # seed 1 jumps to 6 at gen 3
    assert van["wall_time_to_target_s"] == 3.0 and van["env_steps_to_target"] == 300.0
    assert cma["generations_to_target"] is None and cma["reached_target"] == "0/2"
    assert cma["wall_time_s"] == 6.0 and cma["cpu_time_s"] == 12.0 and cma["env_steps"] == 300.0
    assert ours["time_split_s"] == pytest.approx({"gen_time_s": 3.0, "rollout_time_s": 1.5, "time_mphi_s": 0.3})
    assert ours["final_mphi_test_loss"] == 0.5
    json.dumps(s, allow_nan=False)  # NaN-free


def test_summary_cut_to_generations(runs):
    from shaped_es.benchmark.summary import load_runs

    groups, _ = group_runs(runs)
    s = summarize({k: load_runs(v, generations=2) for k, v in groups.items()})
    assert s["methods"]["vanilla"]["final_test_reward_mean"] == 1.5  # last finite of [1, 2] and [1, -]
    assert s["methods"]["vanilla"]["generations"] == 2


def test_report_files(runs, tmp_path):
    groups, configs = group_runs(runs)
    out = write_report(tmp_path / "rep" / "report.md", groups, configs)
    md = (tmp_path / "rep" / "report.md").read_text()
    assert (tmp_path / "rep" / "figures" / "fig4_test_reward.png").stat().st_size > 10_000
    assert out["fig5"] and (tmp_path / "rep" / "figures" / "fig5_mphi_loss.png").is_file()
    assert "![Fig. 5](figures/fig5_mphi_loss.png)" in md
    assert "| vanilla | 2 | 5.00 ± " in md
    assert "time_mphi_s" in md
    summary = json.loads((tmp_path / "rep" / "summary.json").read_text())
    assert set(summary["methods"]) == {"vanilla", "cmaes", "shaped"}
    assert summary["figures"]["fig4"] == "figures/fig4_test_reward.png"


def test_report_without_mphi_columns_notes_it(runs, tmp_path):
    groups, configs = group_runs(runs[:4])
    out = write_report(tmp_path / "rep" / "report.md", groups, configs)
    assert out["fig5"] is None
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "_Not drawn: no run logs `mphi_train_loss`" in md
    assert not (tmp_path / "rep" / "figures" / "fig5_mphi_loss.png").exists()
