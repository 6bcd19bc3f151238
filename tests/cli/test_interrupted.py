"""A Ctrl-C that lands inside a library's constructor (CI caught one in NumPy's ``np.savez``: ``ZipFile``
half-built, its ``__del__`` failing when the traceback was freed) ends with the command's one line only;
what the half-built object's clean-up raised goes to the run's ``error.log``."""

import argparse
import gc
import sys

from shaped_es.cli import commands, prune
from shaped_es.cli.errors import WarningRoute


class HalfBuilt:
    """Like ``zipfile.ZipFile``: ``__del__`` reads an attribute its ``__init__`` sets after a slow step."""

    def __init__(self):
        raise KeyboardInterrupt  # the signal arrives in the slow step, before ``self._writing`` is set

    def __del__(self):
        self.close()

    def close(self):
        if self._writing:
            pass


def _interrupted(_a):
    HalfBuilt()


def test_ctrl_c_inside_a_constructor_prints_only_the_interrupted_line(monkeypatch, capsys, tmp_path):
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", seen.append)  # Python's would print "Exception ignored in ..."
    monkeypatch.setattr(prune, "cmd_prune", _interrupted)
    assert commands.main(["prune", str(tmp_path)]) == 130
    gc.collect()
    assert capsys.readouterr().err.splitlines() == ["shaped-es: interrupted"]
    assert seen == []


def test_what_the_half_built_object_raised_goes_to_error_log_uncounted(capsys, tmp_path):
    (tmp_path / "run").mkdir()
    route = WarningRoute(argparse.Namespace(command="train", out=str(tmp_path / "run")), debug=False)
    try:
        HalfBuilt()
    except KeyboardInterrupt as exc:
        route.release_interrupted(exc)
    route.close()  # nothing to count: the interruption made it
    assert capsys.readouterr().err == ""
    log = (tmp_path / "run" / "error.log").read_text()
    assert "after the interruption" in log and "AttributeError" in log and "_writing" in log


def test_without_the_release_the_half_built_object_does_raise_on_its_own(monkeypatch):
    """The tests above can fail: freed without the release, the same object reaches Python's hook (which
    prints "Exception ignored in ...")."""
    seen = []
    monkeypatch.setattr(sys, "unraisablehook", seen.append)
    try:
        HalfBuilt()
    except KeyboardInterrupt:
        pass
    gc.collect()
    assert [u.exc_type for u in seen] == [AttributeError]
