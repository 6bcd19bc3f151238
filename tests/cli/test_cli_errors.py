"""How a command ends on a lost simulator server or an env that raised mid-run: one line that names the resume
command (for a plain env error, once the env is fixed: a resume imports the env's module as it is then)."""

import argparse

from shaped_es.cli.errors import USAGE_ERROR, error_line
from shaped_es.rollout import EnvError


def test_a_worker_fault_names_the_resume_command_and_a_plain_env_error_names_it_after_a_fix(tmp_path):
    a = argparse.Namespace(command="train", out=str(tmp_path / "run"))
    (tmp_path / "run").mkdir()
    (tmp_path / "run" / "config.yaml").write_text("env: CarlaNav-v0\n")  # the hint names only a run that exists
    lost = EnvError("env 'CarlaNav-v0' raised CarlaServerLost: CarlaNav-v0: the CARLA server at localhost:2000 "
                    "stopped answering (time-out of 10000ms)", "Traceback ...", worker_fault=True)
    line, code = error_line(lost, a, debug=False)
    assert code == USAGE_ERROR and "\n" not in line
    assert line.startswith("shaped-es: error: env 'CarlaNav-v0' raised CarlaServerLost")
    assert f"; continue with: shaped-es resume {tmp_path / 'run'} (traceback in" in line
    line, _ = error_line(EnvError("env 'X' raised ValueError: bad", "Traceback ..."), a, debug=False)
    assert f"bad; once the env is fixed, continue with: shaped-es resume {tmp_path / 'run'} (traceback in" in line
    fresh = argparse.Namespace(command="train", out=str(tmp_path / "never"))  # no run was left: no hint
    line, _ = error_line(EnvError("env 'X' raised ValueError: bad", "Traceback ..."), fresh, debug=False)
    assert "resume" not in line


def test_an_env_error_in_evaluate_or_render_says_to_run_it_again_once_fixed(tmp_path):
    """A new user's env raised in ``evaluate``: the line named the seed but, unlike train's, not what to do."""
    (tmp_path / "run").mkdir()
    for command in ("evaluate", "render"):
        a = argparse.Namespace(command=command, run_dir=str(tmp_path / "run"))
        line, code = error_line(EnvError("env 'X' raised ValueError: bad", "Traceback ..."), a, debug=False)
        assert code == USAGE_ERROR and "\n" not in line
        assert f"bad; once the env is fixed, run shaped-es {command} again (the run is unchanged) (traceback in" in line


def test_the_run_of_a_command_is_its_run_dir_before_its_out():
    """render's --out is its GIF: a traceback of render goes to the run's error.log, not beside a file name."""
    import argparse

    from shaped_es.cli.errors import _run_dir

    assert _run_dir(argparse.Namespace(run_dir="runs/a", out="video.gif")) == "runs/a"
    assert _run_dir(argparse.Namespace(out="runs/new")) == "runs/new"
    assert _run_dir(argparse.Namespace(run_dir="runs/a")) == "runs/a"
    assert _run_dir(argparse.Namespace()) is None
