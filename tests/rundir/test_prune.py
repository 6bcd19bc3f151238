"""Pruning a finished run (``rundir/prune.py``): the data only an exact resume reads goes, what evaluate and
load_policy read stays, the run is marked so that the run loop refuses to resume it, a locked, unfinished
or unreadable run is skipped, and nothing the run did not write is touched. The command: tests/cli."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys

import pytest
import yaml

from helpers import CARTPOLE_TINY, SHAPED_TINY, SRC, train
from shaped_es.config import build_config
from shaped_es.run_loop import run_finished
from shaped_es.rundir.prune import DATA_DIRS, PRUNED_NAME, plan_prune, prune_run, refuse_pruned
from shaped_es.rundir.store import RunStore, StoreError
from shaped_es.trainer import Trainer
from shaped_es.trained.evaluate import evaluate_run
from shaped_es.trained.load import load_policy

KEPT = ["config.yaml", "run.json", "metrics.csv", "label_probe.json", "label_probe_candidate.npy",
        "checkpoints/gen_000003.npz", "checkpoints/gen_000003.json", "checkpoints/latest.json"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished tiny shaped run (trained once; each test prunes its own copy)."""
    return train(tmp_path_factory.mktemp("shaped") / "run", SHAPED_TINY).root


@pytest.fixture
def run(finished, tmp_path):
    return shutil.copytree(finished, tmp_path / "run")


def snapshot(root):
    return {str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.rglob("*")) if p.is_file()}


def _size(root):
    return sum(p.lstat().st_size for p in root.rglob("*") if p.is_file() and not p.is_symlink())


def test_prune_frees_the_resume_data_and_keeps_what_evaluate_reads(run):
    assert {d.name for d in run.iterdir() if d.name.startswith("mphi_data")} >= {"mphi_data", "mphi_data_rival"}
    before, size = evaluate_run(run, episodes=2, executor="inline"), _size(run)
    kept = {k: v for k, v in snapshot(run).items() if k in KEPT}
    res = prune_run(run, run_finished)
    assert res.status == "pruned" and res.parts[-1] == "2 older checkpoints"
    assert res.nbytes == size - _size(run) + (run / PRUNED_NAME).stat().st_size and res.nbytes > 500_000
    assert not [p for p in run.iterdir() if p.name.startswith("mphi_data") or p.name == "trajectories"]
    assert sorted(p.name for p in (run / "checkpoints").iterdir()) == ["gen_000003.json", "gen_000003.npz",
                                                                      "latest.json"]
    assert {k: v for k, v in snapshot(run).items() if k in KEPT} == kept  # not a byte changed
    after = evaluate_run(run, episodes=2, executor="inline")
    assert after["episode_returns"] == before["episode_returns"]
    assert load_policy(run).generation == before["policy_generation"]
    again = prune_run(run, run_finished)
    assert (again.status, again.nbytes, again.notes) == ("nothing", 0, ["already pruned"])


def test_the_run_loop_refuses_a_pruned_run_and_changes_nothing(run):
    prune_run(run, run_finished)
    before = snapshot(run)
    store = RunStore(run)
    cfg = build_config({**SHAPED_TINY, "generations": 5})
    with pytest.raises(StoreError, match="was pruned on .* cannot be resumed or extended; evaluate, render and "
                                         "report use it as it is") as exc:
        Trainer(cfg, store, progress=False).run()
    assert "\n" not in str(exc.value)
    with pytest.raises(StoreError, match="was pruned"):
        refuse_pruned(store)
    assert snapshot(run) == before and not (run / ".lock").exists()


def test_dry_run_changes_nothing_and_says_what_would_go(run):
    before = snapshot(run)
    dry = prune_run(run, run_finished, dry_run=True)
    assert dry.status == "would prune" and snapshot(run) == before
    assert "resume would refuse it afterwards (evaluate, render and report still work)" in dry.notes  # said first
    real = prune_run(run, run_finished)
    assert (real.nbytes, real.parts) == (dry.nbytes, dry.parts)


def test_an_unfinished_run_is_skipped_unless_forced(run):
    cfg = yaml.safe_load((run / "config.yaml").read_text())
    (run / "config.yaml").write_text(yaml.safe_dump({**cfg, "generations": 5}))  # 3 of 5 done
    before = snapshot(run)
    res = prune_run(run, run_finished)
    assert res.status == "skipped" and res.why.startswith("unfinished (3 of 5 generations done)")
    assert snapshot(run) == before
    assert prune_run(run, run_finished, force=True).status == "pruned"
    assert (run / PRUNED_NAME).is_file() and not (run / "mphi_data").exists()


def test_a_run_stopped_at_its_threshold_is_finished(tmp_path):
    store = train(tmp_path / "r", {**SHAPED_TINY, "generations": 6, "stop_at": -1e9})
    assert store.newest_generation() < 6  # stopped early, as finished
    assert prune_run(store.root, run_finished).status == "pruned"


HOLD = """
import sys, time
from shaped_es.rundir.store import RunStore
with RunStore(sys.argv[1]).lock():
    print("locked", flush=True)
    time.sleep(60)
"""


def test_a_run_another_process_holds_is_never_pruned(run):
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(run)], stdout=subprocess.PIPE, text=True,
                              env={**os.environ, "PYTHONPATH": str(SRC)})
    try:
        assert holder.stdout.readline().strip() == "locked"
        before = snapshot(run)
        for kw in ({}, {"dry_run": True}, {"force": True}):
            res = prune_run(run, run_finished, **kw)
            assert res.status == "skipped" and f"is in use by process {holder.pid}" in res.why
        assert snapshot(run) == before
    finally:
        holder.kill()
        holder.wait()
    assert prune_run(run, run_finished).status == "pruned"  # its lock died with it


def test_only_the_runs_own_files_go(run, tmp_path):
    outside = tmp_path / "precious.npz"
    outside.write_bytes(b"keep")
    theirs = ["mphi_data/notes.txt", "trajectories/mine/members_0000-0001.parquet",
              "trajectories/gen_000002/extra.txt", "checkpoints/gen_000001.npz.bak", "data/added_000001.npz"]
    for rel in theirs:
        (run / rel).parent.mkdir(parents=True, exist_ok=True)
        (run / rel).write_text("x")
    (run / "mphi_data_rival" / "added_000099.npz").symlink_to(outside)  # a symlink is not followed
    res = prune_run(run, run_finished)
    assert res.status == "pruned" and res.notes[0].startswith("kept 4 file(s) the run did not write")
    assert all((run / rel).is_file() for rel in theirs) and outside.read_bytes() == b"keep"
    assert sorted(p.name for p in (run / "mphi_data").iterdir()) == ["notes.txt"]
    assert (run / "mphi_data_rival" / "added_000099.npz").is_symlink()
    assert not (run / "trajectories" / "gen_000001").exists()


def test_a_folder_that_is_no_run_is_skipped(tmp_path):
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "mphi_data").mkdir()
    (tmp_path / "notes" / "mphi_data" / "added_000001.npz").write_text("x")
    res = prune_run(tmp_path / "notes", run_finished)
    assert res.status == "skipped" and "not a run directory (no config.yaml)" in res.why
    assert (tmp_path / "notes" / "mphi_data" / "added_000001.npz").is_file()


def test_a_run_that_loses_only_older_checkpoints_stays_resumable(tmp_path):
    store = train(tmp_path / "v", {**CARTPOLE_TINY, "executor": "inline", "generations": 4})
    res = prune_run(store.root, run_finished)
    assert res.parts == ["2 older checkpoints"] and "it stays resumable (only older checkpoints go)" in res.notes
    assert not (store.root / PRUNED_NAME).exists() and store.checkpoints() == [4]
    Trainer(build_config({**CARTPOLE_TINY, "executor": "inline", "generations": 5}), store, progress=False).run()
    assert len(store.read_metrics()) == 5


def test_every_data_folder_a_shaped_run_writes_is_known(finished):
    from shaped_es.guides import rival

    assert {rival.DIR, rival.SERVO_DIR, rival.SHOOT_DIR, rival.SHOOT_BASE_DIR, rival.SHOOT_THIRD_DIR,
            "mphi_data"} == set(DATA_DIRS)
    written = {p.name for p in finished.iterdir() if p.name.startswith("mphi_data")}
    assert written and written <= set(DATA_DIRS)
    assert plan_prune(RunStore(finished)).resume_data
