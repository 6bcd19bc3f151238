"""The line before the shaping kernels compile: printed only when Numba's cache is cold, by runs of the
methods that use the kernels, and not with ``--quiet`` (``progress=False``)."""

import pytest
from helpers import CARTPOLE_TINY

from shaped_es.config import build_config
from shaped_es.shaping import kernel_notice
from shaped_es.trainer import startup_notice
from shaped_es.shaping import kernels


@pytest.mark.parametrize("cached, said", [(False, True), (True, False), (None, False)])
def test_the_line_comes_only_before_a_compile(monkeypatch, capsys, cached, said):
    monkeypatch.setattr(kernels, "cached", lambda fns=None: cached)
    assert kernel_notice.say_if_compiling("train") is said
    err = capsys.readouterr().err
    assert err == (f"[train] {kernel_notice.NOTICE}\n" if said else "")


def test_kernels_off_compile_nothing(monkeypatch, capsys):
    monkeypatch.setattr(kernels, "cached", lambda fns=None: False)
    monkeypatch.setattr(kernels, "ENABLED", False)  # SHAPED_ES_KERNELS=0: the NumPy reference runs
    assert not kernel_notice.say_if_compiling("train") and capsys.readouterr().err == ""


@pytest.mark.parametrize("method, progress, said", [("shaped", True, True), ("shaped_cmaes", True, True),
                                                    ("shaped", False, False), ("vanilla", True, False),
                                                    ("ppo", True, False)])
def test_a_run_says_it_when_its_method_compiles_them(monkeypatch, capsys, method, progress, said):
    monkeypatch.setattr(kernels, "cached", lambda fns=None: False)  # a cold cache
    assert startup_notice(build_config({**CARTPOLE_TINY, "method": method}), progress, "train") is said
    assert ("compiling the shaping kernels" in capsys.readouterr().err) is said
