"""``shaped-es bench strategies``: tiny sizes, the JSON's keys, the table, the CMA-ES memory skip."""

import argparse
import json

import pytest

from shaped_es.speed.strategy_speed import cmaes_bytes, parse_size, parse_sizes
from shaped_es.cli.commands import main

PHASES = {"ask_ms", "tell_ms", "gen_ms"}


def _run(capsys, *args):
    rc = main(["bench", "strategies", "--generations", "2", "--warmup", "1", "--pairs", "2", "--k", "3",
               *args])
    assert rc == 0
    return capsys.readouterr().out


def test_bench_strategies_json(capsys):
    out = _run(capsys, "--sizes", "300,25k", "--json")
    assert len(out.strip().splitlines()) == 1  # one JSON line
    res = json.loads(out)
    assert {"benchmark", "unit", "blas_threads", "sizes", "strategies", "pairs", "popsize", "k",
            "generations", "warmup", "results", "skipped", "numpy", "python"} <= set(res)
    assert res["sizes"] == [300, 25_000] and res["blas_threads"] == 1 and res["popsize"] == 4
    assert res["strategies"] == ["vanilla", "guided", "cmaes"] and res["skipped"] == []
    got = {(r["strategy"], r["n"]): r for r in res["results"]}
    assert set(got) == {(s, n) for s in ("vanilla", "guided", "cmaes") for n in (300, 25_000)}
    for (name, n), r in got.items():
        keys = PHASES | ({"guide_ms"} if name == "guided" else set())
        assert keys <= set(r) and all(r[k] >= 0 for k in keys), r
        assert r["gen_ms"] >= r["ask_ms"] and r["popsize"] == 4
        assert r["k"] == (3 if name == "guided" else 0)
    assert got[("guided", 300)]["population_dtype"] == "float64"  # small policies: float64 path
    assert got[("guided", 25_000)]["population_dtype"] == "float32"  # large: float32 path
    assert got[("cmaes", 25_000)]["population_dtype"] == "float64"


def test_bench_strategies_skips_cmaes_above_the_memory_cap_and_prints_a_table(capsys):
    out = _run(capsys, "--sizes", "2.4k", "--strategies", "cmaes,vanilla", "--cmaes-max-gb", "0.0001",
               "--json")
    res = json.loads(out)
    assert [r["strategy"] for r in res["results"]] == ["vanilla"]
    (skip,) = res["skipped"]
    assert skip["strategy"] == "cmaes" and skip["n"] == 2400 and "GB" in skip["reason"]
    table = _run(capsys, "--sizes", "500", "--strategies", "guided,cmaes", "--cmaes-max-gb", "0.0001")
    assert "guide ms" in table and "guided" in table and "skipped" in table


def test_sizes_and_bad_arguments(capsys):
    assert parse_size("2.4k") == 2400 and parse_size("100k") == 100_000 and parse_size("1M") == 1_000_000
    assert parse_sizes("2400, 1m") == (2400, 1_000_000)
    assert cmaes_bytes(1_000_000, 64) > 4e9  # the default run skips cmaes at 1M
    for bad in ("x", "0", "1.5", "-3k"):
        with pytest.raises(argparse.ArgumentTypeError):
            parse_size(bad)
    for args in (["--sizes", "12q"], ["--strategies", "pso"], ["--generations", "0"]):
        with pytest.raises(SystemExit) as e:
            main(["bench", "strategies", *args])
        assert e.value.code == 2


def test_speed_is_the_command_and_bench_its_alias(capsys):
    for name in ("speed", "bench"):
        with pytest.raises(SystemExit) as info:
            main([name, "--help"])
        assert info.value.code == 0
        assert "shaping" in capsys.readouterr().out
