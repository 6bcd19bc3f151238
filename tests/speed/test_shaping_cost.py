"""``shaped-es speed shaping``: a vanilla and a shaped run side by side; the JSON has what it promises."""

from __future__ import annotations

import json

import pytest

from shaped_es.speed.shaping_cost import PHASES, bench_shaping, format_table
from shaped_es.cli.commands import main


@pytest.mark.slow  # 11-19 s of real processes: the full suite runs it (CI's fast suite stays under 10 min)
def test_side_by_side_report_has_ratio_phases_and_lower_bound():
    over = {"shaping.inverse_dynamics.filter": "none", "shaping.inverse_dynamics.steps_per_generation": 20,
            "shaping.cloning.steps": 2}
    res = bench_shaping(("UR5Reach-v0",), generations=2, warmup=2, executor="inline", overrides=over)
    (e,) = res["envs"]
    assert e["env"] == "UR5Reach-v0" and e["timed_generations"] == 2
    assert e["vanilla_generation_s"] > 0 and e["shaped_generation_s"] > 0
    assert abs(e["ratio"] - e["shaped_generation_s"] / e["vanilla_generation_s"]) < 1e-9
    assert set(PHASES) <= set(e["shaped_phases_s"]) and e["shaped_phases_s"]["checkpoint_s"] > 0
    assert e["shaped_phases_s"]["time_cloning_s"] > 0  # the shaping work really ran
    assert e["lower_bound_s"]["mphi"] > 0 and e["lower_bound_s"]["label_and_clone"] > 0
    assert e["shaping"]["clone_steps"] == 2 and e["shaping"]["mphi_steps"] == 20  # --set reached shaped only
    assert res["kernels"]["enabled"] and res["kernels"]["load_s"] >= 0  # their one-time cost, apart
    assert "UR5Reach-v0" in format_table(res)
    json.dumps(res)


def test_cli_rejects_a_bad_override_in_one_line(capsys):
    rc = main(["speed", "shaping", "--envs", "UR5Reach-v0", "--set", "shaping.cloning.steps=-1"])
    err = capsys.readouterr().err
    assert rc == 2 and err.startswith("shaped-es: error:") and len(err.strip().splitlines()) == 1
