"""Benchmark reruns compare settings per run, on the fields that run's method uses: changing one
method's settings reuses every other method's runs; a changed run with finished generations is refused
in one line naming it (delete it to redo it), one without a checkpoint restarts. And the README's
4-method benchmark on a built-in env, with its default methods and time limits, end to end."""

import argparse
import json
import shutil

import pytest

from shaped_es.benchmark.cli_commands import add_benchmark_parser
from shaped_es.benchmark.plan import method_digest
from shaped_es.config import build_config
from shaped_es.rundir.store import RunStore, StoreError

TINY = ["--env", "CartPole-v1", "--seeds", "1", "--executor", "inline", "--quiet",
        "--set", "es.pairs=2", "--set", "rollout.max_steps=50", "--set", "rollout.test_episodes=2",
        "--set", "policy.hidden=[4]", "--set", "tensorboard=false", "--set", "ppo.n_steps=128",
        "--set", "ppo.n_epochs=1", "--no-estimate"]


def _cli(*argv):
    p = argparse.ArgumentParser()
    add_benchmark_parser(p.add_subparsers(dest="command"))
    a = p.parse_args(["benchmark", *map(str, argv)])
    return a.fn(a)


def _status(out):
    s = json.loads((out / "summary.json").read_text())["this_invocation"]
    return {k: v["status"] for k, v in s.items()}


def _metrics(out, name):
    return (out / "runs" / name / "metrics.csv").read_text()


def test_method_digest_ignores_what_the_method_does_not_use():
    base = {"env": "CartPole-v1"}

    def same(method, change):
        a = build_config({**base, "method": method})
        b = build_config({**base, "method": method, **change})
        return method_digest(a) == method_digest(b)

    assert same("vanilla", {"ppo": {"n_epochs": 3}}) and same("cmaes", {"shaping": {"eta": 0.1}})
    assert same("vanilla", {"es": {"alpha": 0.5}}) and not same("guided", {"es": {"alpha": 0.5}})
    assert same("ppo", {"es": {"sigma": 0.3}}) and not same("ppo", {"es": {"pairs": 3}})
    assert not same("ppo", {"ppo": {"n_epochs": 3}}) and not same("shaped", {"shaping": {"eta": 0.1}})
    assert same("cmaes", {"es": {"lr": 0.5}}) and not same("cmaes", {"es": {"cmaes_mu": 3}})
    assert not same("vanilla", {"rollout": {"episodes": 3}})  # shared settings count for everyone
    assert same("vanilla", {"generations": 9, "workers": 2})  # where and how long, not what


def test_rerun_with_one_methods_settings_changed_reuses_the_others(tmp_path):
    out = tmp_path / "b"
    assert _cli(*TINY, "--methods", "vanilla,cmaes,ppo", "--generations", 1, "--out", out) == 0
    es_before = {m: _metrics(out, f"{m}_s0") for m in ("vanilla", "cmaes")}
    changed = [*TINY, "--set", "ppo.n_epochs=2", "--methods", "vanilla,cmaes,ppo"]
    with pytest.raises(StoreError) as exc:  # the PPO run has a finished generation: refused, nothing run
        _cli(*changed, "--generations", 1, "--out", out)
    msg = str(exc.value)
    assert "\n" not in msg and "ppo_s0" in msg and "ppo.n_epochs" in msg and "delete" in msg
    assert "vanilla_s0" not in msg and "cmaes_s0" not in msg
    shutil.rmtree(out / "runs" / "ppo_s0")  # as the message says
    assert _cli(*changed, "--generations", 1, "--out", out) == 0
    assert _status(out) == {"vanilla_s0": "skipped", "cmaes_s0": "skipped", "ppo_s0": "new"}
    assert {m: _metrics(out, f"{m}_s0") for m in ("vanilla", "cmaes")} == es_before
    assert RunStore(out / "runs" / "ppo_s0").read_config().ppo.n_epochs == 2
    # extending keeps each run's own config: the ES runs resume with their checkpoints' settings
    assert _cli(*changed, "--generations", 2, "--out", out) == 0
    assert _status(out) == {"vanilla_s0": "resumed", "cmaes_s0": "resumed", "ppo_s0": "resumed"}
    assert _metrics(out, "vanilla_s0").startswith(es_before["vanilla"])
    assert len(_metrics(out, "cmaes_s0").strip().splitlines()) == 3


def test_a_benchmark_of_another_env_into_the_same_folder_says_so(tmp_path):
    # a new user pointed a second env's benchmark at the first's folder: it was told to delete "those" runs
    out = tmp_path / "b"
    assert _cli(*TINY, "--methods", "vanilla", "--generations", 1, "--out", out) == 0
    other = [a if a != "CartPole-v1" else "Pendulum-v1" for a in TINY]
    with pytest.raises(StoreError) as exc:
        _cli(*other, "--methods", "vanilla", "--generations", 1, "--out", out)
    assert str(exc.value) == (f"{out} holds a benchmark of another env (CartPole-v1), not Pendulum-v1: a benchmark "
                              f"folder is one env's; use another --out")


def test_a_rerun_with_fewer_methods_says_its_page_leaves_runs_out(tmp_path, capsys):
    """A new user extended vanilla and cmaes only; the page then lacked the shaped runs, and nothing said so."""
    out = tmp_path / "b"
    assert _cli(*TINY, "--methods", "vanilla,cmaes", "--generations", 1, "--out", out) == 0
    assert "also holds" not in capsys.readouterr().err
    assert _cli(*TINY, "--methods", "vanilla", "--generations", 2, "--out", out) == 0
    lines = [ln for ln in capsys.readouterr().err.splitlines() if "also holds" in ln]
    assert lines == [f"[benchmark] report.md shows this invocation's methods and seeds; {out / 'runs'} also holds "
                     f"cmaes_s0 (1): shaped-es report {out} --out {out / 'report.md'} draws them all"]
    assert "longer:" not in capsys.readouterr().err
    # the vanilla-only page above holds all its runs' rows; the advice's command redraws the whole page there
    from shaped_es.cli.commands import main

    assert main(["report", str(out), "--out", str(out / "report.md")]) == 0
    # a rerun with a smaller budget than the runs have (a new user's): the page cuts them there, and says so
    capsys.readouterr()
    assert _cli(*TINY, "--methods", "vanilla", "--generations", 1, "--out", out) == 0
    lines = [ln for ln in capsys.readouterr().err.splitlines() if "longer:" in ln]
    assert lines == ["[benchmark] report.md reads every run up to generation 1 (this --generations); longer: "
                     "vanilla_s0 (2 generations): their lines above are their last rows; --generations 2 (or "
                     "shaped-es report, which reads each run to its end) uses them whole"]


def test_a_changed_run_without_checkpoint_restarts(tmp_path):
    out = tmp_path / "b"
    cfg = build_config({"env": "CartPole-v1", "method": "vanilla", "es": {"pairs": 7}})
    RunStore(out / "runs" / "vanilla_s0").create(cfg)  # a run that never finished a generation
    assert _cli(*TINY, "--methods", "vanilla", "--generations", 1, "--out", out) == 0
    assert _status(out) == {"vanilla_s0": "new"}
    assert RunStore(out / "runs" / "vanilla_s0").read_config().es.pairs == 2


def test_a_changed_run_without_checkpoint_holding_a_users_file_is_refused_and_nothing_deleted(tmp_path):
    """A new user's notes.txt in a run folder that never checkpointed: the rerun with other settings deletes
    nothing (the restart used to delete the whole folder) and says in one line what is in the way."""
    out = tmp_path / "b"
    run = out / "runs" / "vanilla_s0"
    RunStore(run).create(build_config({"env": "CartPole-v1", "method": "vanilla", "es": {"pairs": 7}}))
    (run / "notes.txt").write_text("mine")
    (run / "figures").mkdir()
    (run / "figures" / "reward.png").write_bytes(b"png")  # a run's own file beside it
    before = sorted(p.relative_to(run) for p in run.rglob("*"))
    with pytest.raises(StoreError, match=r"holds a run with other settings and no checkpoint, to be started again, "
                                         r"but also files no run writes \(notes\.txt\); move them away"):
        _cli(*TINY, "--methods", "vanilla", "--generations", 1, "--out", out)
    assert sorted(p.relative_to(run) for p in run.rglob("*")) == before
    assert (run / "notes.txt").read_text() == "mine"
    (run / "notes.txt").unlink()  # moved away: the restart goes on, its own files replaced
    assert _cli(*TINY, "--methods", "vanilla", "--generations", 1, "--out", out) == 0
    assert _status(out) == {"vanilla_s0": "new"} and RunStore(run).read_config().es.pairs == 2


def test_four_method_benchmark_on_a_builtin_env_with_defaults(tmp_path):
    out = tmp_path / "car"
    # default methods (shaped, vanilla, cmaes, ppo) and the env's own horizon; only sizes made tiny
    assert _cli("--env", "CarNav-v0", "--seeds", 1, "--generations", 2, "--executor", "inline", "--quiet",
                "--set", "es.pairs=2", "--set", "rollout.episodes=1", "--set", "rollout.test_episodes=2",
                "--set", "policy.hidden=[8]", "--set", "tensorboard=false",
                "--set", "shaping.inverse_dynamics.steps_per_generation=20", "--set", "shaping.cloning.steps=2",
                "--set", "ppo.n_steps=128", "--set", "ppo.n_epochs=1", "--out", out) == 0
    s = json.loads((out / "summary.json").read_text())
    assert list(s["methods"]) == ["shaped", "vanilla", "cmaes", "ppo"]
    assert (out / "report.md").is_file()
    for m in s["methods"]:
        assert len(_metrics(out, f"{m}_s0").strip().splitlines()) == 3


def test_stop_at_ends_runs_early_and_a_rerun_skips_them(tmp_path):
    out = tmp_path / "b"
    # CartPole's test reward is at least 1: every run reaches --stop-at 1 at its first evaluation
    assert _cli(*TINY, "--methods", "vanilla,ppo", "--generations", 4, "--stop-at", 1, "--out", out) == 0
    assert _status(out) == {"vanilla_s0": "new", "ppo_s0": "new"}
    assert len(_metrics(out, "vanilla_s0").strip().splitlines()) == 1 + 2  # its row 0, and generation 1's
    assert len(_metrics(out, "ppo_s0").strip().splitlines()) == 1 + 1
    assert _cli(*TINY, "--methods", "vanilla,ppo", "--generations", 4, "--stop-at", 1, "--out", out) == 0
    assert _status(out) == {"vanilla_s0": "skipped", "ppo_s0": "skipped"}  # finished, as far as they go
    assert _cli(*TINY, "--methods", "vanilla", "--generations", 4, "--out", out) == 0  # without it: continued
    assert _status(out) == {"vanilla_s0": "resumed"}
    assert len(_metrics(out, "vanilla_s0").strip().splitlines()) == 1 + 4
