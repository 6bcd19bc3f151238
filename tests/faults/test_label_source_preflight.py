"""A shaped run whose label source cannot serve (``shaping.labels=reference`` without a usable
``shaping.reference_run``, ``controller`` on an env without the hook) fails before its run directory is
written: one error line, exit 2, no ``--out``, so the corrected command trains into the same ``--out``."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from shaped_es.cli.commands import main

TINY = ["--method", "shaped", "--generations", "1", "--pairs", "4", "--executor", "inline", "--set",
        "rollout.episodes=1", "--set", "rollout.test_episodes=1", "--set", "tensorboard=false", "--quiet"]
CARNAV = "CarNav-v0"
REACH = "fault_envs:Reach-v0"  # the waypoint contract, no scripted controller


@pytest.fixture(scope="module")
def reference_run(tmp_path_factory) -> Path:
    """A finished (tiny) vanilla run of CarNav-v0: a reference whose policy can give labels."""
    root = tmp_path_factory.mktemp("reference") / "run"
    argv = ["train", "--env", CARNAV, *TINY, "--method", "vanilla", "--out", str(root)]
    assert main(argv) == 0
    return root


def _unfinished(ref: Path, tmp: Path) -> str:
    """A run directory with its config but no checkpoint yet (a run that never got going)."""
    run = tmp / "unfinished"
    run.mkdir()
    for name in ("config.yaml", "run.json"):
        shutil.copy(ref / name, run / name)
    return str(run)


# id, env, bad settings, fixed settings, needle of the error line
CASES = [
    ("reference-without-run", CARNAV, lambda ref, tmp: ["shaping.labels=reference"],
     lambda ref, tmp: ["shaping.labels=reference", f"shaping.reference_run={ref}"],
     "shaping.labels=reference needs shaping.reference_run"),
    ("reference-run-missing", CARNAV,
     lambda ref, tmp: ["shaping.labels=reference", f"shaping.reference_run={tmp / 'nothing'}"],
     lambda ref, tmp: ["shaping.labels=reference", f"shaping.reference_run={ref}"],
     "it does not exist"),
    ("reference-run-unfinished", CARNAV,
     lambda ref, tmp: ["shaping.labels=reference", f"shaping.reference_run={_unfinished(ref, tmp)}"],
     lambda ref, tmp: ["shaping.labels=reference", f"shaping.reference_run={ref}"],
     "has no checkpoint yet"),
    ("controller-without-hook", REACH, lambda ref, tmp: ["shaping.labels=controller"],
     lambda ref, tmp: ["shaping.labels=mphi"], "shaping.labels=controller needs a scripted waypoint controller"),
]


def _argv(env: str, settings: list[str], out: Path) -> list[str]:
    sets = [x for s in settings for x in ("--set", s)]
    return ["train", "--env", env, *TINY, *sets, "--out", str(out)]


@pytest.mark.parametrize("env, bad, fixed, needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_label_source_error_writes_nothing_and_the_fixed_command_trains_into_the_same_out(
        env, bad, fixed, needle, reference_run, tmp_path, capsys, faults_path):
    out = tmp_path / "run"
    capsys.readouterr()
    assert main(_argv(env, bad(reference_run, tmp_path), out)) == 2
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("shaped-es: error: "), err
    assert needle in lines[0], lines[0]
    assert not out.exists(), sorted(p.name for p in out.iterdir())  # nothing that would refuse the retry
    assert main(_argv(env, fixed(reference_run, tmp_path), out)) == 0, capsys.readouterr().err
    assert (out / "config.yaml").is_file() and (out / "checkpoints").is_dir()


def test_the_setup_time_check_still_guards_direct_use(faults_path):
    """``label_source`` (the shaped guide's setup) refuses the same configs, for callers that skip preflight."""
    from shaped_es.config import ConfigError, build_config
    from shaped_es.guides.shaped_setup import label_source
    from shaped_es.rollout import policy_spec, probe_env

    cfg = build_config({"env": REACH, "method": "shaped", "shaping": {"labels": "controller"}})
    probe = probe_env(cfg.env, cfg.env_kwargs)
    with pytest.raises(ConfigError, match="scripted waypoint controller"):
        label_source(cfg, policy_spec(cfg, probe), None, None, None, probe)
    cfg = build_config({"env": REACH, "method": "shaped", "shaping": {"labels": "reference"}})
    with pytest.raises(ConfigError, match="needs shaping.reference_run"):
        label_source(cfg, policy_spec(cfg, probe), None, None, None, probe)


def test_the_command_line_process_leaves_no_run_and_retries_into_the_same_out(tmp_path):
    """The same through ``python -m shaped_es`` in a process of its own."""
    from fault_run import run_cli

    out = tmp_path / "run"
    res = run_cli(*_argv(CARNAV, ["shaping.labels=reference"], out), prefix=["-m", "shaped_es"])
    assert res.returncode == 2, res.stderr
    assert res.stderr.strip().splitlines() == ["shaped-es: error: shaping.labels=reference needs "
                                               "shaping.reference_run (a finished run of this env whose best "
                                               "policy gives the labels)"]
    assert not out.exists()
    res = run_cli(*_argv(CARNAV, [], out), prefix=["-m", "shaped_es"])
    assert res.returncode == 0, res.stderr
