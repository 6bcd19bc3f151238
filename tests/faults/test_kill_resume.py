"""SIGKILL the trainer at every step of a checkpoint, resume, and compare with an uninterrupted run row
for row: vanilla, cmaes, shaped (checkpoint_every 1 and 3) and ppo.

The kill points (``killer.py``): the ``.npz`` in a temporary file, the ``.npz`` renamed, the ``.json``
renamed, ``latest.json`` renamed, and half of a metrics row written. After ``resume`` the run directory
must hold no temporaries, half checkpoints or lock, ``latest.json`` must name the newest checkpoint, and
the metrics must equal the uninterrupted run's (PPO, which restarts its training episodes on resume by
design, must equal it up to the checkpoint resumed from and continue with one row per generation).
"""

from __future__ import annotations

import json

import pytest
from fault_run import HERE, config, leftovers, run_cli, write_config
from helpers import strip_time, train
from killer import POINTS

from shaped_es.rundir.store import RunStore

GEN = 3  # the checkpoint written after generation index 2 (of 6)
FAST = {("vanilla", p) for p in POINTS} | {("cmaes", "npz_tmp"), ("cmaes", "latest")}


def _marks(m: str, p: str) -> list:
    return [] if (m, p) in FAST else [pytest.mark.slow]


CASES = [pytest.param(m, p, id=f"{m}-{p}", marks=_marks(m, p))
         for m in ("vanilla", "cmaes", "shaped", "shaped_ce3", "ppo") for p in POINTS]
_REFERENCE: dict[str, list[dict]] = {}


def _reference(method: str, tmp_path_factory) -> list[dict]:
    if method not in _REFERENCE:
        # the uninterrupted run is trained in this process (the Trainer the command line runs, one process
        # start-up less; faults_path makes fault_envs importable here); the killed runs are processes
        d = tmp_path_factory.mktemp(f"ref_{method}")
        _REFERENCE[method] = train(d / "run", config(method)).read_metrics()
    return _REFERENCE[method]


@pytest.mark.parametrize("method, point", CASES)
def test_kill_at_checkpoint_step_then_resume(method, point, tmp_path, tmp_path_factory, faults_path):
    _kill_resume_compare(method, point, GEN, tmp_path, tmp_path_factory)


@pytest.mark.parametrize("point", ["npz_tmp", "json_rename", "metrics_append"])
def test_kill_during_the_first_checkpoint(point, tmp_path, tmp_path_factory, faults_path):
    # without latest.json, resume used to restart at generation 0 and keep row 0: a duplicate
    _kill_resume_compare("vanilla", point, 1, tmp_path, tmp_path_factory)


def test_finished_run_without_latest_json_resumes_to_nothing_new(tmp_path, tmp_path_factory, faults_path):
    ref = _reference("vanilla", tmp_path_factory)
    cfg = write_config(tmp_path / "cfg.yaml", config("vanilla"))
    run = tmp_path / "run"
    assert run_cli("train", "--config", cfg, "--out", run, "--quiet").returncode == 0
    before = {p.name: p.read_bytes() for p in (run / "checkpoints").iterdir() if p.name != "latest.json"}
    (run / "checkpoints" / "latest.json").unlink()
    res = run_cli("resume", run, "--quiet")
    assert res.returncode == 0, res.stderr
    assert strip_time(RunStore(run).read_metrics()) == strip_time(ref)  # 6 rows, not 12
    after = {p.name: p.read_bytes() for p in (run / "checkpoints").iterdir() if p.name != "latest.json"}
    assert after == before  # no checkpoint overwritten
    assert json.loads((run / "checkpoints" / "latest.json").read_text())["name"] == "gen_000006"


def _kill_resume_compare(method, point, gen, tmp_path, tmp_path_factory):
    ref = _reference(method, tmp_path_factory)
    cfg = write_config(tmp_path / "cfg.yaml", config(method))
    run = tmp_path / "run"
    killed = run_cli("train", "--config", cfg, "--out", run, "--quiet",
                     prefix=[str(HERE / "killer.py"), point, str(gen)])
    assert killed.returncode == -9, killed.stderr[-3000:]  # the kill landed
    res = run_cli("resume", run, "--quiet")
    assert res.returncode == 0, res.stderr[-3000:]
    assert leftovers(run) == []
    store = RunStore(run)
    rows = store.read_metrics()
    assert [int(r["generation"]) for r in rows] == list(range(6))
    newest = store.checkpoints()[-1]
    assert newest == 6 and json.loads((run / "checkpoints" / "latest.json").read_text())["name"] == "gen_000006"
    if method == "ppo":  # exact up to the checkpoint it resumed from (gen GEN-1 or GEN)
        assert strip_time(rows)[: gen - 1] == strip_time(ref)[: gen - 1]
    else:
        assert strip_time(rows) == strip_time(ref)


@pytest.mark.slow
@pytest.mark.parametrize("what", ["shard", "folder"])
def test_resume_with_a_deleted_trajectory_shard_is_loud(what, tmp_path, tmp_path_factory, faults_path):
    import shutil

    ref = _reference("shaped", tmp_path_factory)
    cfg = write_config(tmp_path / "cfg.yaml", config("shaped", generations=4))
    run = tmp_path / "run"
    assert run_cli("train", "--config", cfg, "--out", run, "--quiet").returncode == 0
    gen = sorted((run / "trajectories").iterdir())[-1]
    if what == "shard":
        for f in gen.iterdir():
            f.unlink()
    else:
        shutil.rmtree(run / "trajectories")
    res = run_cli("resume", run, "--generations", "6", "--quiet")
    if res.returncode == 2:  # a loud, one-line error: fine
        assert len(res.stderr.strip().splitlines()) == 1 and "traject" in res.stderr
    else:  # or the same rows as if nothing had been deleted
        assert strip_time(RunStore(run).read_metrics()) == strip_time(ref)
