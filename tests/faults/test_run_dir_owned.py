"""A run directory is a folder the run owns: ``train --out`` refuses a non-empty folder that holds no
run and the empty path (a real process each), and resume's clean-up deletes only the temporaries of
files the run writes, in the run's own folders, never a user's file elsewhere in the tree."""

from __future__ import annotations

import pytest
from fault_run import one_error_line, run_cli, snapshot

from shaped_es.rundir.store import RunStore, StoreError

TINY = ["--env", "CartPole-v1", "--method", "vanilla", "--generations", "1", "--pairs", "2", "--executor",
        "inline", "--set", "rollout.test_episodes=1", "--set", "tensorboard=false", "--quiet"]


def _user_folder(root):
    (root / "notes").mkdir(parents=True)
    (root / "notes" / ".draft.md.tmp").write_text("a user's draft")
    (root / "notes" / "todo.txt").write_text("x")
    return root


def test_train_refuses_a_folder_of_other_files(tmp_path):
    folder = _user_folder(tmp_path / "project")
    before = snapshot(folder)
    res = run_cli("train", *TINY, "--out", folder)
    assert res.returncode == 2
    assert "holds no run but other files (notes)" in one_error_line(res.stderr)
    assert snapshot(folder) == before and sorted(p.name for p in folder.iterdir()) == ["notes"]


def test_train_refuses_an_empty_out_path(tmp_path):
    (tmp_path / "keep.txt").write_text("x")
    res = run_cli("train", *TINY, "--out", "", cwd=tmp_path)
    assert res.returncode == 2
    assert "--out is empty" in one_error_line(res.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.txt"]


def test_train_takes_an_empty_folder_and_a_failed_start(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    assert run_cli("train", *TINY, "--out", empty).returncode == 0
    failed = tmp_path / "failed"  # what a start that failed before its config leaves
    failed.mkdir()
    (failed / "run.json").write_text('{"run_id": "0123456789abcdef"}')
    (failed / "error.log").write_text("old traceback\n")
    (failed / ".config.yaml.abc123.tmp").write_text("half")
    assert run_cli("train", *TINY, "--out", failed).returncode == 0


def test_check_new_names_the_cases(tmp_path):
    with pytest.raises(StoreError, match="--out is empty"):
        RunStore("").check_new()
    _user_folder(tmp_path / "p")
    with pytest.raises(StoreError, match="holds no run but other files"):
        RunStore(tmp_path / "p").check_new()
    RunStore(tmp_path / "absent").check_new()


def test_clean_temporaries_touches_only_the_runs_own_files(tmp_path):
    store = RunStore(tmp_path / "run")
    ours = [".metrics.csv.k2j3_x.tmp", ".label_probe_candidate.npy.a1b2.tmp", ".position_period.json.zz9.tmp",
            "checkpoints/.gen_000003.npz.abcd1234.tmp",
            "checkpoints/.latest.json.x1.tmp", "mphi_data/.added_000002.npz.q.tmp",
            "mphi_data_rival/.added_000005.npz.oo4zgge6.tmp", "mphi_data_shoot_third/.added_000001.npz.a.tmp",
            "trajectories/gen_000001/.members_0000-0003.parquet.0123abcd.tmp", "figures/.reward.png.x1.tmp"]
    theirs = ["notes/.draft.md.tmp", ".notes.txt.x.tmp", ".label_probe_candidate.npy.bak", "checkpoints/.mine.tmp",
              "tb/.events.x.tmp", "figures/.fig4_test_reward.png.x.tmp", "figures/old.png",
              "trajectories/other/.members_0000-0003.parquet.a.tmp",
              "deep/checkpoints/.gen_000001.npz.a.tmp", "mphi_data/sub/.added_000002.npz.q.tmp"]
    for rel in ours + theirs:
        p = store.root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text("x")
    removed = store.clean_temporaries()
    assert sorted(str(p.relative_to(store.root)) for p in removed) == sorted(ours)
    assert all((store.root / rel).is_file() for rel in theirs)
