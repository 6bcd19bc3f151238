"""Benchmark variants: named settings of a method, run and reported as methods of their own."""

from __future__ import annotations

import pytest

from shaped_es.benchmark.spec import BenchmarkSpec, run_configs
from shaped_es.cli.commands import main
from shaped_es.config import ConfigError


def test_variant_configs_carry_their_overrides_and_base_method():
    spec = BenchmarkSpec(env="CartPole-v1", methods=("vanilla", "wide"), seeds=(0, 1), generations=3,
                         variants={"wide": {"method": "vanilla", "es.sigma": 0.2}})
    cfgs = run_configs(spec)
    assert list(cfgs) == ["vanilla_s0", "wide_s0", "vanilla_s1", "wide_s1"]
    assert cfgs["wide_s1"].method == "vanilla" and cfgs["wide_s1"].es.sigma == 0.2
    assert cfgs["vanilla_s1"].es.sigma != 0.2 and cfgs["wide_s1"].seed == 1


@pytest.mark.parametrize("variants", [{"vanilla": {"method": "vanilla"}}, {"x": {"method": "nope"}},
                                      {"x": {"es.sigma": 0.1}}])
def test_bad_variants_are_one_clear_error(variants):
    with pytest.raises(ConfigError, match="--variant"):
        BenchmarkSpec(env="CartPole-v1", methods=("vanilla",), seeds=(0,), generations=1, variants=variants)


def test_cli_variant_end_to_end(tmp_path, capsys):
    out = tmp_path / "b"
    rc = main(["benchmark", "--env", "CartPole-v1", "--methods", "vanilla,wide", "--seeds", "2",
               "--generations", "2", "--executor", "inline", "--out", str(out), "--quiet",
               "--set", "rollout.test_episodes=2", "--set", "es.pairs=4", "--set", "tensorboard=false",
               "--variant", "wide=vanilla,es.sigma=0.3", "--threshold", "50"])
    assert rc == 0, capsys.readouterr().err
    assert (out / "runs" / "wide_s1" / "metrics.csv").is_file()
    assert "wide" in (out / "report.md").read_text()
