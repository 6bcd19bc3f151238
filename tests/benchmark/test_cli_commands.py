"""``--seeds``: a count or a range (two new users typed ``--seeds 0-9``), checked against ``--first-seed``."""

import argparse

import pytest

from shaped_es.benchmark.cli_commands import seed_list, seeds_arg
from shaped_es.cli.commands import build_parser
from shaped_es.config import ConfigError


def test_count_and_range_parse():
    assert seeds_arg("10") == 10
    assert seeds_arg("0-9") == (0, 9)
    assert seeds_arg(" 100 - 109 ") == (100, 109)
    for bad in ("9-0", "a-b", "0..9", "ten"):
        with pytest.raises(argparse.ArgumentTypeError):
            seeds_arg(bad)


def test_seed_list():
    assert seed_list(3, None) == (0, 1, 2)
    assert seed_list(3, 5) == (5, 6, 7)
    assert seed_list((100, 102), None) == (100, 101, 102)
    assert seed_list((100, 102), 100) == (100, 101, 102)
    with pytest.raises(ConfigError, match="disagrees"):
        seed_list((100, 102), 0)
    for n, first in ((0, None), (-1, None), (3, -1)):
        with pytest.raises(ConfigError, match="positive"):
            seed_list(n, first)


def test_parser_takes_a_range():
    p = build_parser()
    a = p.parse_args(["benchmark", "--env", "PointVel-v0", "--seeds", "0-9", "--out", "x"])
    assert seed_list(a.seeds, a.first_seed) == tuple(range(10))
    a = p.parse_args(["suite", "run", "--out", "x", "--seeds", "2"])
    assert seed_list(a.seeds, a.first_seed) == (0, 1)
