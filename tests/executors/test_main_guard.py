"""A script that calls ``shaped_es.train`` with the process executor outside ``if __name__ ==
"__main__":`` (issue 29): its workers would import it again and start the run again in each. It ends with
one line naming the guard and exit code 2, before anything is written; with the guard it trains."""

import os
import subprocess
import sys
import types

import pytest

from helpers import SRC
from shaped_es.executors import main_guard

RUN = ('shaped_es.train({"env": "CartPole-v1", "method": "vanilla", "generations": 1, "executor": "process", '
       '"workers": 1, "es.pairs": 2, "rollout.test_episodes": 1, "tensorboard": False}, "runs/r")')


def _as_main(monkeypatch, tmp_path, source: str, name: str = "__main__", file: bool = True) -> dict:
    """Run ``source`` as the ``__main__`` script ``script.py``; its globals."""
    path = tmp_path / "script.py"
    path.write_text(source)
    main = types.ModuleType(name)
    if file:
        main.__file__ = str(path)
    monkeypatch.setitem(sys.modules, "__main__", main)
    exec(compile(source, str(path), "exec"), vars(main))
    return vars(main)


CHECK = "from shaped_es.executors.main_guard import unguarded_call\n"


@pytest.mark.parametrize("source, line", [
    (CHECK + "found = unguarded_call()\n", 2),
    (CHECK + "def main():\n    return unguarded_call()\n\n\nfound = main()\n", 6),  # via a function: its call
    (CHECK + 'if __name__ == "__main__":\n    found = unguarded_call()\n', None),
    (CHECK + "if '__main__' == __name__:\n    x = 1\n    found = unguarded_call()\n", None),
    (CHECK + 'if __name__ != "__main__":\n    pass\nelse:\n    found = unguarded_call()\n', 5),  # not the guard
    (CHECK + "found = (\n    unguarded_call()\n)\n", 3),  # a statement over lines: the line of the call
])
def test_an_unguarded_top_level_call_is_found(monkeypatch, tmp_path, source, line):
    found = _as_main(monkeypatch, tmp_path, source, name="__main__")["found"]
    assert found == (None if line is None else f"{tmp_path / 'script.py'}:{line}")


def test_no_script_file_or_a_call_from_elsewhere_passes(monkeypatch, tmp_path):
    assert _as_main(monkeypatch, tmp_path, CHECK + "found = unguarded_call()\n", file=False)["found"] is None
    assert main_guard.unguarded_call() is None  # pytest's own __main__ is guarded, and not on this path


def test_a_worker_importing_the_script_again_refuses_to_start_a_run(monkeypatch, tmp_path):
    src = "from shaped_es.executors.main_guard import refuse_in_worker\nrefuse_in_worker()\n"
    with pytest.raises(RuntimeError, match='put the script\'s top level under if __name__ == "__main__":'):
        _as_main(monkeypatch, tmp_path, src, name="__mp_main__")
    _as_main(monkeypatch, tmp_path, src, name="__main__")  # the parent: nothing to refuse


def _script(tmp_path, body: str) -> subprocess.CompletedProcess:
    (tmp_path / "script.py").write_text("import shaped_es\n\n" + body)
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    return subprocess.run([sys.executable, "script.py"], cwd=tmp_path, env=env, capture_output=True, text=True,
                          timeout=300)


def test_an_unguarded_script_is_one_line_exit_2_and_nothing_written(tmp_path):
    res = _script(tmp_path, f"rows = {RUN}\n")
    assert res.returncode == 2 and res.stdout == ""
    assert res.stderr.splitlines() == [
        f"shaped-es: error: {tmp_path / 'script.py'}:3 starts worker processes from the script's top level: put "
        f'the call under if __name__ == "__main__": (each worker imports the script again, which would start the '
        f"run again; or use executor='inline'); nothing was written"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["script.py"]


def test_a_guarded_script_trains(tmp_path):
    res = _script(tmp_path, f'if __name__ == "__main__":\n    print(len({RUN}))\n')
    assert res.returncode == 0 and res.stdout.strip() == "1", res.stderr
