"""``shaped-es suite``: every (task, method, seed) run resumably with progress lines, one table in Markdown
and JSON, the budgets table, the acceptance rate and the thresholds from the registered EnvSpecs."""

import json

import numpy as np
import pytest

from shaped_es.benchmark.suite import SUITES, acceptance, run_suite, suite_tasks, write_suite_report
from shaped_es.benchmark.summary import builtin_threshold
from shaped_es.cli.commands import main
from shaped_es.config import ConfigError
from shaped_es.rundir.store import StoreError

TINY = {"executor": "inline", "tensorboard": False, "rollout.test_episodes": 3, "es.pairs": 4}


def test_two_tasks_two_seeds_run_resume_and_report(tmp_path):
    logs = []
    res = run_suite(tmp_path, tasks=["PointVel-v0", "Unicycle-v0"], methods=("shaped", "vanilla"), seeds=(0, 1),
                    generations=2, overrides=TINY, progress=False, log=logs.append)
    assert sum("new" in m for m in logs if m.startswith("[suite] ") and "runs (" in m) == 8
    assert any(m.startswith("[suite] 8/8 runs") for m in logs)  # progress: runs done of all
    data = json.loads((tmp_path / "suite.json").read_text())
    assert [r["task"] for r in data["tasks"]] == ["PointVel-v0", "Unicycle-v0"]
    row = data["tasks"][0]
    assert row["threshold"]["value"] == 8.5 and "reward_threshold" in row["threshold"]["source"]
    assert row["budget_generations"] == 2 and set(row["methods"]) == {"shaped", "vanilla"}
    for m in row["methods"].values():
        assert m["seeds"] == 2 and m["final_iqm"] is not None and len(m["final_iqm_ci"]) == 2
    vanilla, shaped = row["methods"]["vanilla"], row["methods"]["shaped"]
    assert vanilla["solved"] == 0 and vanilla["generations_to_threshold"] == 3.0  # censored at 2 + 1
    # the shaped runs may solve in 2 generations (the label probe's candidate, judged beside generation 0)
    assert row["ratios"]["vs_vanilla"]["generations_to_threshold"] == shaped["generations_to_threshold"] / 3.0
    assert row["best_baseline"] == "vanilla" and "acceptance" in row["methods"]["shaped"]
    md = (tmp_path / "suite.md").read_text()
    assert "| PointVel-v0 | 8.50 | 2 |" in md and "| Unicycle-v0 |" in md
    assert res["report"].endswith("suite.md")
    # a rerun skips every finished run and rewrites the same table
    logs.clear()
    run_suite(tmp_path, tasks=["PointVel-v0", "Unicycle-v0"], methods=("shaped", "vanilla"), seeds=(0, 1),
              generations=2, overrides=TINY, progress=False, log=logs.append)
    assert sum("skipped" in m for m in logs) == 8 and not any(": new" in m for m in logs)
    assert json.loads((tmp_path / "suite.json").read_text())["tasks"] == data["tasks"]
    # another method on one task, into the same folder: the table keeps every run (it showed the last call's alone)
    run_suite(tmp_path, tasks=["Unicycle-v0"], methods=("cmaes",), seeds=(0, 1), generations=2, overrides=TINY,
              progress=False, log=logs.append)
    both = json.loads((tmp_path / "suite.json").read_text())
    assert both["methods"] == ["shaped", "vanilla", "cmaes"] and [r["task"] for r in both["tasks"]] == [
        "PointVel-v0", "Unicycle-v0"]
    assert set(both["tasks"][0]["methods"]) == {"shaped", "vanilla"}  # no CMA-ES runs there: "–" in the table
    assert set(both["tasks"][1]["methods"]) == {"shaped", "vanilla", "cmaes"}
    assert both["tasks"][0]["ratios"] == data["tasks"][0]["ratios"]


def test_acceptance_rate_pools_generations_with_a_candidate():
    runs = [{"candidate_accepted": np.array([np.nan, 0, 1, 1]), "candidate_gain": np.array([np.nan, -1, 2, 2])},
            {"candidate_accepted": np.array([0.0, 0.0]), "candidate_gain": np.array([-3.0, -1.0])}]
    a = acceptance(runs)
    assert (a["accepted"], a["generations"]) == (2, 5) and a["rate"] == pytest.approx(0.4)
    assert a["mean_gain"] == pytest.approx(-0.2)
    assert acceptance([{"generation": np.arange(3)}])["rate"] is None  # vanilla: no candidate column


def test_suite_table_and_thresholds():
    envs = [t.env for t in SUITES["waypoints"]]
    assert {"PointVel-v0", "PointForce-v0", "Unicycle-v0", "ReacherWay-v0", "CarNav-v0", "UR5Reach-v0"} <= set(envs)
    for t in SUITES["waypoints"]:
        assert t.generations > 0 and builtin_threshold(t.env) is not None
    assert [t.env for t in suite_tasks("waypoints", ["Unicycle-v0", "PointVel-v0"])] == ["PointVel-v0", "Unicycle-v0"]
    with pytest.raises(ConfigError, match="not in suite"):
        suite_tasks("waypoints", ["Pendulum-v1"])
    with pytest.raises(StoreError, match="no suite"):
        write_suite_report("/nonexistent/suite")


def test_cli_bad_input_is_one_line(capsys, tmp_path):
    assert main(["suite", "run", "--out", str(tmp_path / "x"), "--tasks", "Nope-v0"]) == 2
    assert "not in suite" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()


def test_estimate_only_prints_each_task_and_writes_nothing(tmp_path):
    logs = []
    res = run_suite(tmp_path / "s", tasks=["Unicycle-v0"], methods=("vanilla",), seeds=(0, 1), generations=3,
                    overrides=TINY, progress=False, estimate_only=True, log=logs.append)
    assert set(res["estimate_s"]) == {"Unicycle-v0"} and res["estimate_s"]["Unicycle-v0"] > 0
    assert any(m.startswith("[suite] Unicycle-v0: estimate: vanilla: 2 runs") for m in logs)
    assert logs[-1].startswith("[suite] estimate: total") and not (tmp_path / "s").exists()
