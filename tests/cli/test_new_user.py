"""What a new user meets (issue 29): a run ``--stop-at`` ended says why ``resume`` runs nothing and how to
continue it (``--no-stop-at``, a higher ``--stop-at``); the ``--stop-at`` line quotes the row that crossed;
``--preset`` on an env without presets, ``--set tensorboard=yes`` and a misspelt nested key (with the field
it may mean, however the key is written) are one line each; ``shaped-es envs`` prints no MuJoCo warnings
(and leaves no ``MUJOCO_LOG.TXT``)."""

import json
import os
import subprocess
import sys

import pytest

from helpers import CARTPOLE_TINY, SRC, new_run, popen_cli, strip_time, train
from shaped_es.cli.commands import main
from shaped_es.config import ConfigError, build_config, merge, parse_set
from shaped_es.rundir.store import RunStore
from shaped_es.trainer import Trainer

TINY = ["--executor", "inline", "--pairs", "2", "--set", "rollout.episodes=1", "--set", "rollout.test_episodes=2",
        "--set", "policy.hidden=[4]", "--set", "tensorboard=false", "--quiet"]


def _err_lines(capsys):
    return [line for line in capsys.readouterr().err.strip().splitlines() if line]


def test_resume_of_a_run_stop_at_ended_says_why_and_continues_with_no_stop_at(tmp_path, capsys):
    full, run = str(tmp_path / "full"), str(tmp_path / "run")
    assert main(["train", "--env", "CartPole-v1", *TINY, "--generations", "5", "--out", full]) == 0
    # CartPole scores >= 1: --stop-at 1 ends the run after its first evaluated row (2 rows)
    assert main(["train", "--env", "CartPole-v1", *TINY, "--generations", "5", "--stop-at", "1", "--out", run]) == 0
    capsys.readouterr()
    assert main(["resume", run, "--generations", "7", "--quiet"]) == 2  # asks for generations that cannot run
    (line,) = _err_lines(capsys)
    assert line.startswith(f"shaped-es: error: {run} ended as finished after 2 generations: a test reward of ")
    assert f"reached its --stop-at 1, so nothing would run; to continue it: shaped-es resume {run} " \
           f"--generations 7 --no-stop-at (or --stop-at R with R above " in line
    assert main(["resume", run, "--quiet"]) == 0  # nothing asked: the old result, and one line saying why
    (line,) = _err_lines(capsys)
    assert line.startswith(f"shaped-es: {run} ended as finished after 2 generations") and "nothing ran" in line
    assert len(RunStore(run).read_metrics()) == 2
    assert main(["resume", run, "--no-stop-at", "--quiet"]) == 0  # continues, exactly as the unstopped run
    assert strip_time(RunStore(run).read_metrics()) == strip_time(RunStore(full).read_metrics())
    assert RunStore(run).read_config().stop_at is None
    capsys.readouterr()
    assert main(["resume", run, "--quiet"]) == 0  # all done (not stopped): its result again, and one line
    assert _err_lines(capsys) == [f"shaped-es: {run} has all its 5 generations done: nothing ran, its result is "
                                  f"printed again (--generations N above 5 continues it)"]


def test_resume_with_a_higher_stop_at_continues(tmp_path, capsys):
    run = str(tmp_path / "run")
    assert main(["train", "--env", "CartPole-v1", *TINY, "--generations", "4", "--stop-at", "1", "--out", run]) == 0
    assert main(["resume", run, "--stop-at", "1e9", "--quiet"]) == 0
    assert len(RunStore(run).read_metrics()) == 4 and RunStore(run).read_config().stop_at == 1e9
    with pytest.raises(SystemExit) as exc:  # one or the other (argparse's one line)
        main(["resume", run, "--stop-at", "1", "--no-stop-at"])
    assert exc.value.code == 2 and "not allowed with argument" in _err_lines(capsys)[-1]


def test_resume_of_a_stop_at_run_as_a_process(tmp_path):
    run = tmp_path / "run"
    new = popen_cli("train", "--env", "CartPole-v1", *TINY, "--generations", "4", "--stop-at", "1",
                    "--out", str(run))
    assert new.wait(timeout=300) == 0, new.stderr.read()
    p = popen_cli("resume", str(run), "--generations", "6")
    out, err = p.communicate(timeout=300)
    assert p.returncode == 2 and out == ""
    assert err.splitlines() == [err.strip()] and "--no-stop-at" in err


def test_the_stop_at_line_quotes_the_row_that_crossed(tmp_path, capsys):
    """Test rewards 28.7, 22.7, ... (tests/test_run_loop.py): --stop-at 25 is crossed at the first row; the
    second (22.7, already run) is written too, and the line must quote 28.67, not the last row's."""
    cfg, store = new_run(tmp_path / "r", {**CARTPOLE_TINY, "executor": "inline", "generations": 5, "stop_at": 25})
    rows = Trainer(cfg, store, progress=True).run()
    assert [round(r["test_reward_mean"]) for r in rows] == [29, 23]
    line = [x for x in _err_lines(capsys) if "stopped after" in x]
    assert line == ["[train] stopped after 2 of 5 generations: gen 1's test reward of 28.67 reached --stop-at 25"]


def test_preset_on_an_env_without_presets_is_one_line(tmp_path, capsys):
    out = tmp_path / "r"
    assert main(["train", "--env", "Pendulum-v1", "--preset", "paper", *TINY, "--out", str(out)]) == 2
    (line,) = _err_lines(capsys)
    assert line.startswith("shaped-es: error: env 'Pendulum-v1' has no presets: drop --preset") \
        and "TypeError" not in line and not out.exists()
    assert main(["train", "--env", "Pendulum-v1", "--set", "env_kwargs.scale=2", *TINY, "--out", str(out)]) == 2
    assert _err_lines(capsys) == ["shaped-es: error: cannot make env 'Pendulum-v1': it takes no keyword argument "
                                  "'scale' (given in env_kwargs)"]


@pytest.mark.parametrize("how, text", [
    ("--set", "shaping.mean_clone.acept=paired"),
    ("--set", "shaping.mean_clone={acept: paired}"),
    ("--config", "shaping:\n  mean_clone:\n    acept: paired\n"),
    ("--config", "shaping.mean_clone.acept: paired\n"),  # a --set key copied into the file
    ("--config", "shaping:\n  mean_clone.acept: paired\n"),
])
def test_a_misspelt_nested_key_is_one_line_with_what_it_may_mean(how, text, tmp_path, capsys):
    cfg = tmp_path / "c.yaml"
    cfg.write_text(text)
    given = ["--set", text] if how == "--set" else ["--config", str(cfg)]
    out = tmp_path / "r"
    assert main(["train", "--env", "CartPole-v1", "--method", "shaped", *TINY, *given, "--out", str(out)]) == 2
    assert _err_lines(capsys) == ["shaped-es: error: invalid config: shaping.mean_clone.acept: unknown field "
                                  "(did you mean accept or accept_flat?)"]
    assert not out.exists()


@pytest.mark.parametrize("word", ["yes", "no", "on", "off", "Yes", "1"])
def test_booleans_are_true_or_false(word, tmp_path, capsys):
    with pytest.raises(ConfigError, match=f"tensorboard: Input should be a valid boolean, true or false"):
        build_config(merge({}, parse_set([f"tensorboard={word}"])))
    assert main(["train", "--env", "CartPole-v1", *TINY, "--set", f"tensorboard={word}",
                 "--out", str(tmp_path / "r")]) == 2
    assert len(_err_lines(capsys)) == 1 and not (tmp_path / "r").exists()
    assert build_config(merge({}, parse_set(["tensorboard=false", "wandb.mode=offline"]))).tensorboard is False
    assert build_config(merge({}, parse_set(["tensorboard=True"]))).tensorboard is True


def test_envs_prints_no_mujoco_warnings(tmp_path):
    pytest.importorskip("mujoco")
    env = {**os.environ, "PYTHONPATH": str(SRC)}
    res = subprocess.run([sys.executable, "-m", "shaped_es.cli.commands", "envs"], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0 and "Ant-v5" in res.stdout  # a MuJoCo env, made and listed
    assert "WARNING" not in res.stdout + res.stderr and res.stderr == ""
    assert list(tmp_path.iterdir()) == []  # no MUJOCO_LOG.TXT


def _own_env_section() -> str:
    readme = (SRC.parent / "README.md").read_text()
    assert "\n## Your own env\n" in readme  # examples/reacher_waypoints.py points here
    assert '(README, "Your own env")' in " ".join((SRC.parent / "examples" / "reacher_waypoints.py").read_text().split())
    return readme.split("\n## Your own env\n", 1)[1].split("\n## ", 1)[0]


def test_the_readme_says_how_to_bring_an_own_env_and_its_example_passes_check_env(tmp_path, monkeypatch, capsys):
    import re

    section = _own_env_section()
    flat = " ".join(section.split())
    assert "registers it with `gymnasium.register` when it is imported" in flat
    assert 'info["position"]' in flat and 'info["waypoint"]' in flat and "shaped-es check-env" in flat
    code = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(code) == 1 and "gym.register(" in code[0]
    (tmp_path / "readme_point.py").write_text(code[0].replace("MyPoint-v0", "ReadmePoint-v0"))
    (tmp_path / "readme_noreg.py").write_text(code[0].split("\ngym.register(")[0])
    monkeypatch.chdir(tmp_path)
    monkeypatch.syspath_prepend(str(tmp_path))
    assert main(["check-env", "readme_point:ReadmePoint-v0"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert out[-1] == "readme_point:ReadmePoint-v0 trains with: vanilla, guided, cmaes, shaped, shaped_cmaes, ppo"
    # its optional controller (a new user's plane found the method only in the contract's section): check-env scores it
    assert any(ln.startswith("ok    controller     waypoint_controller(obs, info)") for ln in out), out
    # --labels on the user's own env (no batched core: driven episode by episode through Gymnasium)
    assert main(["check-env", "readme_point:ReadmePoint-v0", "--labels"]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert any(ln.startswith("labels: with seed 0 a shaped run picks frame=") for ln in out)
    assert out[-1].startswith("labels: ")
    # the module that forgets to register: one line naming gymnasium.register
    assert main(["train", "--env", "readme_noreg:ReadmeNoreg-v0", *TINY, "--out", "r"]) == 2
    assert _err_lines(capsys) == ["shaped-es: error: cannot make env 'readme_noreg:ReadmeNoreg-v0': its module "
                                  "'readme_noreg' imports but registers no 'ReadmeNoreg-v0': call gymnasium."
                                  "register('ReadmeNoreg-v0', entry_point=...) in it (README, \"Your own env\")"]
    assert not (tmp_path / "r").exists()
    # a typo of the id the module does register: the id it meant (a new user's pmass:PointMas-v0)
    assert main(["train", "--env", "readme_point:ReadmePoin-v0", *TINY, "--out", "r"]) == 2
    assert _err_lines(capsys) == ["shaped-es: error: cannot make env 'readme_point:ReadmePoin-v0': its module "
                                  "'readme_point' imports but registers no 'ReadmePoin-v0'; did you mean "
                                  "readme_point:ReadmePoint-v0?"]


def test_the_readmes_quickstart_ranges_are_the_committed_studys():
    """The Quickstart's figures a newcomer checks are ranges over seeds taken from a committed study at the
    default's code, and the seed-0 values it quotes are that study's (README, "What reproduces exactly")."""
    import csv
    import statistics

    root = SRC.parent
    readme = " ".join((root / "README.md").read_text().split())
    study = root / "docs" / "benchmarks" / "probe_candidate_v14" / "suite" / "CarNav-v0" / "runs"
    gens, late = [], []  # generations (counted from 1) to the first test reward of 200; last 10 generations' mean
    for seed in range(10):
        with open(study / f"shaped_s{seed}" / "metrics.csv") as fh:
            tests = [float(r["test_reward_mean"]) for r in csv.DictReader(fh)]
        assert len(tests) == 80
        gens.append(next(i + 1 for i, t in enumerate(tests) if t >= 200))
        late.append(statistics.mean(tests[-10:]))
    assert (f"200 is passed after **{min(gens):.0f}-{max(gens):.0f} generations (median "
            f"{statistics.median(gens):g})**") in readme
    assert f"the last 10 of 80 generations averages {statistics.mean(late):.1f}" in readme
    assert "seed 0 (the Quickstart's) passes 200 at generation 10" in readme and gens[0] == 10
    with open(root / "docs" / "benchmarks" / "labels_babble_walltime" / "runs" / "shaped_s0" / "metrics.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert f"is {float(rows[1]['test_reward_mean']):.5f} on the reference machine" in readme


@pytest.mark.parametrize("argv,line", [
    (["train", "--env", "CarNav-v0", "--genrations", "3", "--out", "r"],
     "unrecognized arguments: --genrations 3 (--genrations: did you mean --generations?) (usage: shaped-es train --help)"),
    (["suite", "run", "--out", "r", "--tsks", "a"],
     "unrecognized arguments: --tsks a (--tsks: did you mean --tasks?) (usage: shaped-es suite run --help)"),
    (["train", "--env", "CarNav-v0", "--zzz", "--out", "r"], "unrecognized arguments: --zzz (usage: shaped-es train --help)"),
])
def test_a_misspelt_flag_is_one_line_naming_the_commands_help_and_the_closest_flag(argv, line, tmp_path, capsys,
                                                                                  monkeypatch):
    """A new user's finding: argparse named the top-level --help and suggested nothing."""
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    assert capsys.readouterr().err.strip() == f"shaped-es: error: {line}"
    assert not (tmp_path / "r").exists()


def test_resume_says_where_it_picks_up(tmp_path, capsys):
    """A new user's resumed run showed only "gen 13/30", with metrics.csv a row shorter than the checkpoint: resume
    says in one line how many generations its newest checkpoint holds (not under --quiet, nor when nothing runs)."""
    run = str(tmp_path / "r")
    assert main(["train", "--env", "CartPole-v1", *TINY, "--generations", "2", "--out", run, "--quiet"]) == 0
    capsys.readouterr()
    assert main(["resume", run, "--generations", "3"]) == 0
    err = capsys.readouterr().err
    assert (f"shaped-es: {run}: resuming from its newest checkpoint, 2 of 3 generations done (metrics.csv continues "
            f"from there as an uninterrupted run's would)") in err
    assert main(["resume", run, "--generations", "4", "--quiet"]) == 0
    assert "resuming" not in capsys.readouterr().err
    assert main(["resume", run]) == 0  # all done: nothing runs, and its own line says so
    assert "resuming" not in capsys.readouterr().err
