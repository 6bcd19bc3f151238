"""Bad input, table-driven: each case gets exactly one line ``shaped-es: error: ...``, exit code 2, and
leaves everything already saved (a finished run directory) byte for byte as it was.

Cases: flags and config values (non-finite, out of range, wrong types, seeds past 2**32, sizes no
machine holds), config files, run directories (``--out`` unusable), env modules and envs that raise or
return garbage (the env's exception type and message in the line, its traceback in RUN/error.log), and
run directories with damaged files for ``resume`` / ``evaluate``. Disk full, out of memory and a search
that goes non-finite have tests of their own below.
"""

from __future__ import annotations

import errno
import shutil
from pathlib import Path

import numpy as np
import pytest
from fault_run import (drop, edit_json, edit_npz, edit_text, leftovers, module, nothing, replace_with_file,
                        snapshot, write)

from shaped_es.cli.commands import main

TRAIN = ["--executor", "inline", "--generations", "2", "--pairs", "2", "--set", "rollout.episodes=1",
         "--set", "rollout.test_episodes=1", "--set", "policy.hidden=[4]", "--set", "tensorboard=false",
         "--quiet"]
FAULTY = "fault_envs:Faulty-v0"


def train(*extra, env="CartPole-v1"):
    return lambda run, tmp: ["train", "--env", env, *TRAIN, *extra, "--out", str(tmp / "new")]


def resume(*extra):
    return lambda run, tmp: ["resume", str(run), "--quiet", *extra]


def evaluate(*extra):
    return lambda run, tmp: ["evaluate", str(run), "--episodes", "2", *extra]


def faulty(fault):
    return train("--set", f"env_kwargs.fault={fault}", env=FAULTY)


def s(key_value):
    return train("--set", key_value)


def config_folder(run, tmp):
    (run / "config.yaml").unlink()
    (run / "config.yaml").mkdir()


CKPT = "checkpoints/gen_000002"
CASES = [
    # id, damage, command, needle
    ("sigma-inf", nothing, s("es.sigma=.inf"), "es.sigma: Input should be a finite number"),
    ("sigma-1e308", nothing, s("es.sigma=1e308"), "es.sigma"),
    ("sigma-nan", nothing, s("es.sigma=.nan"), "es.sigma"),
    ("lr-inf", nothing, s("es.lr=.inf"), "es.lr"),
    ("eta-1e-300", nothing, train("--method", "shaped", "--set", "shaping.eta=1e-300",
                                  env="fault_envs:Reach-v0"), "shaping.eta"),
    ("pairs-true", nothing, s("es.pairs=true"), "es.pairs: Input should be a valid integer (got true)"),
    ("sigma-empty", nothing, s("es.sigma="), "es.sigma: an empty value; give one (null leaves an optional "
                                             "field unset) (got '')"),
    ("max-steps-empty", nothing, s("rollout.max_steps="), "rollout.max_steps: an empty value"),  # null, silently
    ("seed-2**32", nothing, train("--seed", str(2**32)), "seed: Input should be less than 4294967296"),
    ("hidden-bool", nothing, s("policy.hidden=[8, true]"), "policy.hidden.1"),
    ("hidden-word", nothing, s("policy.hidden=abc"), "policy.hidden: Input should be a list, e.g. its default [32, 32]"),
    ("tensorboard-1", nothing, s("tensorboard=1"), "tensorboard: Input should be a valid boolean"),
    ("episodes-2.5", nothing, s("rollout.episodes=2.5"), "rollout.episodes"),
    ("sigma-true", nothing, s("es.sigma=true"), "es.sigma: Input should be a number, not a boolean"),
    ("optimizer-unknown", nothing, s("es.optimizer=lbfgs"), "es.optimizer"),
    ("checkpoint-every-0", nothing, s("checkpoint_every=0"), "checkpoint_every"),
    ("timeout-negative", nothing, s("task_timeout_s=-1"), "task_timeout_s"),
    ("popsize-odd", nothing, train("--popsize", "7"), "--popsize must be a positive even number"),
    ("workers-100000", nothing, train("--executor", "process", "--workers", "100000"), "--workers 100000"),
    ("hidden-huge", nothing, s("policy.hidden=[100000, 100000]"), "GiB"),
    ("config-binary", write("../bin.yaml", bytes(range(256))),
     lambda run, tmp: ["train", "--config", str(tmp / "bin.yaml"), "--out", str(tmp / "new")], "not a text"),
    ("config-directory", nothing, lambda run, tmp: ["train", "--config", str(tmp), "--out", str(tmp / "new")],
     "is a folder, not a YAML file"),
    ("config-list", write("../list.yaml", "[]"),
     lambda run, tmp: ["train", "--config", str(tmp / "list.yaml"), "--out", str(tmp / "new")],
     "must hold a mapping"),
    ("out-in-proc", nothing, lambda run, tmp: ["train", "--env", "CartPole-v1", *TRAIN, "--out", "/proc/x/y"],
     "cannot create run directory /proc/x/y"),
    ("out-is-a-file", write("../file", "x"),
     lambda run, tmp: ["train", "--env", "CartPole-v1", *TRAIN, "--out", str(tmp / "file")], "not a directory"),
    ("env-unknown", nothing, train(env="NoSuchEnv-v0"), "NoSuchEnv-v0"),
    ("env-kwargs-unknown", nothing, s("env_kwargs.nonsense=1"), "cannot make env 'CartPole-v1'"),
    ("env-import-raises", module("bad_import", "raise RuntimeError('broken module')\n"),
     train(env="bad_import:Env-v0"), "RuntimeError: broken module"),
    ("env-import-syntax", module("bad_syntax", "def broken(:\n    pass\n"), train(env="bad_syntax:Env-v0"),
     "SyntaxError"),
    ("env-raises-in-init", nothing, faulty("raise_init"), "RuntimeError: the simulator failed to start"),
    ("env-raises-in-step", nothing, faulty("raise_step"), "RuntimeError: the simulator lost its connection"),
    ("env-raises-in-reset", nothing, faulty("raise_reset"), "ValueError: reset failed"),
    ("env-nan-reward", nothing, faulty("nan_reward"),  # a bad value mid-run is resumable, as a raise is
     "check the env's step/reset; once the env is fixed, continue with"),
    ("env-nan-obs", nothing, faulty("nan_obs"), "returned a non-finite observation"),
    ("env-changes-shape", nothing, faulty("shape"), "an observation of shape (5,)"),
    # -- resume / evaluate of a damaged run directory
    ("npz-0-bytes", write(f"{CKPT}.npz", b""), resume(), "checkpoint gen_000002 in"),
    ("npz-garbage", write(f"{CKPT}.npz", b"PK\x03\x04garbage"), resume(), "unreadable"),
    ("npz-pickled-object", edit_npz(lambda a: {**a, "x": np.array([{"a": 1}], dtype=object)}), resume(),
     "unreadable"),
    ("npz-missing-arrays", edit_npz(lambda a: {"policy/best": a["policy/best"]}), resume(),
     "does not fit this run"),
    ("npz-wrong-shape", edit_npz(lambda a: {**a, "policy/best": a["policy/best"][:3]}), resume(),
     "does not fit this run"),
    ("json-list", write(f"{CKPT}.json", "[]"), resume(), "unreadable"),
    ("json-only-generation", write(f"{CKPT}.json", '{"generation": 2}'), resume(), "not saved together"),
    ("json-missing-counter", edit_json(f"{CKPT}.json", drop("env_steps")), resume(), "env_steps"),
    ("json-bad-counter", edit_json(f"{CKPT}.json", lambda d: {**d, "env_steps": "many"}), resume(),
     "does not fit this run"),
    ("json-binary", write(f"{CKPT}.json", bytes(range(256))), resume(), "unreadable"),
    ("latest-outside", write("checkpoints/latest.json", '{"name": "../../x"}'), resume(),
     "not a checkpoint of this run"),
    ("latest-missing-newer", write("checkpoints/latest.json", '{"name": "gen_000009"}'), resume(),
     "which is missing"),
    ("metrics-non-numeric", edit_text("metrics.csv", lambda t: t.replace("\n1,", "\nabc,", 1)), resume(),
     "non-numeric"),
    ("metrics-binary", write("metrics.csv", bytes(range(256)) * 4), resume(), "binary"),
    ("metrics-short-row", edit_text("metrics.csv", lambda t: t.replace("\n1,", "\n1,2\n9,", 1)), resume(),
     "fields"),
    ("metrics-header", edit_text("metrics.csv", lambda t: "x" + t), resume(), "header"),
    ("metrics-repeated-row", edit_text("metrics.csv", lambda t: t + t.splitlines(keepends=True)[-1]),
     lambda run, tmp: ["report", str(run), "--out", str(tmp / "r.png")], "does not follow"),  # resume: repaired
    ("config-yaml-binary", write("config.yaml", bytes(range(256))), resume(), "not a text"),
    ("config-yaml-invalid", write("config.yaml", "es: [unclosed\n"), resume(), "not valid YAML"),
    ("config-yaml-inf", edit_text("config.yaml", lambda t: t.replace("sigma: 0.05", "sigma: .inf")), resume(),
     "es.sigma"),
    ("config-changed", edit_text("config.yaml", lambda t: t.replace("seed: 0", "seed: 7")), resume(),
     "different config"),
    ("checkpoints-is-a-file", replace_with_file("checkpoints"), resume(), "is not a directory"),
    ("run-missing", nothing, lambda run, tmp: ["resume", str(tmp / "nothing")], "not a run directory"),
    ("run-is-a-file", write("../afile", "x"), lambda run, tmp: ["resume", str(tmp / "afile")],
     "not a run directory"),
    ("resume-fewer-generations", nothing, resume("--generations", "1"), "fewer"),
    ("evaluate-npz-0-bytes", write(f"{CKPT}.npz", b""), evaluate(), "unreadable"),
    ("evaluate-latest-outside", write("checkpoints/latest.json", '{"name": "../../x"}'), evaluate(),
     "not a checkpoint of this run"),
    ("evaluate-episodes-0", nothing, lambda run, tmp: ["evaluate", str(run), "--episodes", "0"], "--episodes"),
    # issue 30: accepted without a word, an internal error, or a line that did not name the problem
    ("evaluate-seed-negative", nothing, evaluate("--seed", "-1"), "--seed must be an integer from 0 to"),
    ("evaluate-seed-2**64", nothing, evaluate("--seed", str(2**64)), "--seed must be an integer from 0 to"),
    ("json-huge-counter", edit_json(f"{CKPT}.json", lambda d: {**d, "env_steps": 10**30}), resume(),
     "malformed counter 'env_steps'"),
    ("config-yaml-is-a-folder", config_folder, resume(), "config.yaml is a folder, not a regular file"),
    # a run made by an older shaped-es: its config.yaml lacks a setting added since, its digest differs
    ("config-older-version", lambda run, tmp: (
        edit_text("config.yaml", lambda t: "".join(l for l in t.splitlines(keepends=True)
                                                    if "revert_margin" not in l))(run, tmp),
        edit_json(f"{CKPT}.json", lambda d: {**d, "config_digest": "0" * 16})(run, tmp)), resume(),
     "older shaped-es, without the settings shaping.mean_clone.revert_margin"),
]
ENV_EXCEPTIONS = {"env-raises-in-step", "env-raises-in-reset"}  # at run time: traceback in RUN/error.log


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("finished") / "run"
    assert main(["train", "--env", "CartPole-v1", *TRAIN, "--out", str(root)]) == 0
    return root


def test_at_least_40_cases():
    assert len(CASES) >= 40 and len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize("damage, command, needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input_is_one_line_exit_2_and_changes_nothing(damage, command, needle, finished_run, tmp_path,
                                                          capsys, monkeypatch, faults_path):
    run = tmp_path / "run"
    shutil.copytree(finished_run, run)
    (tmp_path / "mods").mkdir()
    monkeypatch.syspath_prepend(str(tmp_path / "mods"))
    damage(run, tmp_path)
    before = snapshot(run)
    capsys.readouterr()
    argv = command(run, tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    lines = [l for l in err.splitlines() if l.strip() and not l.startswith("shaped-es: warning:")]
    assert len(lines) == 1 and lines[0].startswith("shaped-es: error: "), err
    assert needle in lines[0], lines[0]
    assert snapshot(run) == before, "a saved file changed"
    new = tmp_path / "new"
    if new.is_dir():  # only env faults at run time get this far: the directory stays consistent
        assert leftovers(new) == [] and (new / "config.yaml").is_file()
        if any(argv[argv.index("--set") + 1].endswith(f) for f in ("raise_step", "raise_reset")
               if "--set" in argv):
            log = (new / "error.log").read_text()
            assert "Traceback" in log and "fault_envs.py" in log
            assert "(traceback in " in lines[0]


def test_debug_prints_the_env_traceback(tmp_path, capsys, faults_path):
    argv = ["--debug", "train", "--env", FAULTY, *TRAIN, "--set", "env_kwargs.fault=raise_step",
            "--out", str(tmp_path / "r")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and "fault_envs.py" in err
    assert err.strip().splitlines()[-1].startswith("shaped-es: error: env 'fault_envs:Faulty-v0' raised "
                                                   "RuntimeError: the simulator lost its connection")


def test_disk_full_is_one_line_and_leaves_the_run_resumable(tmp_path, capsys, monkeypatch):
    import shaped_es.rundir.checkpoints as checkpoints
    import shaped_es.rundir.store as store

    run = tmp_path / "r"
    real = checkpoints.atomic_write_bytes  # the checkpoints' writes (rundir/checkpoints.py)
    calls = {"n": 0}

    def full(path, data):
        if Path(path).name.endswith(".npz") and Path(path).parent.name == "checkpoints":
            calls["n"] += 1
            if calls["n"] == 2:  # the second checkpoint: disk full
                raise OSError(errno.ENOSPC, "No space left on device", str(path))
        real(path, data)

    monkeypatch.setattr(checkpoints, "atomic_write_bytes", full)
    argv = ["train", "--env", "CartPole-v1", *TRAIN, "--generations", "4", "--out", str(run)]
    assert main(argv) == 2
    line = capsys.readouterr().err.strip().splitlines()[-1]
    assert line.startswith("shaped-es: error: no space left on device") and "last checkpoint" in line
    assert f"shaped-es resume {run}" in line
    monkeypatch.setattr(checkpoints, "atomic_write_bytes", real)
    assert main(["resume", str(run), "--quiet"]) == 0
    assert [int(r["generation"]) for r in store.RunStore(run).read_metrics()] == [0, 1, 2, 3]
    assert leftovers(run) == []


def test_out_of_memory_is_one_line(tmp_path, capsys, monkeypatch):
    from shaped_es.policies import MLPSpec

    def oom(self, seed):
        raise MemoryError("Unable to allocate 40.0 GiB for an array")

    monkeypatch.setattr(MLPSpec, "init", oom)
    assert main(["train", "--env", "CartPole-v1", *TRAIN, "--out", str(tmp_path / "r")]) == 2
    line = capsys.readouterr().err.strip().splitlines()
    assert len(line) == 1 and line[0].startswith("shaped-es: error: out of memory (Unable to allocate")


def test_non_finite_mean_stops_with_one_line_and_keeps_the_last_good_checkpoint(tmp_path, capsys,
                                                                                 monkeypatch):
    from shaped_es.rundir.store import RunStore
    from shaped_es.strategies.vanilla import VanillaES

    tell = VanillaES.tell
    seen = {"n": 0}

    def diverging(self, fitness):
        tell(self, fitness)
        seen["n"] += 1
        if seen["n"] == 3:  # generation 2's update overflows
            bad = np.full_like(self._mean, np.inf)
            bad.flags.writeable = False
            self._mean = bad

    monkeypatch.setattr(VanillaES, "tell", diverging)
    run = tmp_path / "r"
    assert main(["train", "--env", "CartPole-v1", *TRAIN, "--generations", "5", "--out", str(run)]) == 2
    line = capsys.readouterr().err.strip().splitlines()
    assert len(line) == 1 and "generation 3: the search mean became non-finite" in line[0]
    assert "last good checkpoint (generation 2) is kept" in line[0]
    store = RunStore(run)
    arrays, meta = store.load_checkpoint()
    assert meta["generation"] == 2 and all(np.isfinite(v).all() for v in arrays.values()
                                           if v.dtype.kind == "f")
    assert leftovers(run) == []


def test_a_negative_number_after_its_option_is_taken(tmp_path, capsys):
    run = tmp_path / "r"
    assert main(["train", "--env", "CartPole-v1", *TRAIN, "--stop-at", "-1e9", "--out", str(run)]) == 0
    from shaped_es.rundir.store import RunStore

    assert RunStore(run).read_config().stop_at == -1e9
