"""rundir/run_files.py: a run directory without a checkpoint is replaced only when it holds nothing but what a
run writes; anything else (a user's file, a symlink, a folder of another name) refuses it with nothing deleted."""

import pytest

from shaped_es.rundir.atomic import StoreError
from shaped_es.rundir.run_files import foreign_entries, replace_run_dir

RUN = ["config.yaml", "run.json", "metrics.csv", ".lock", "error.log", "label_probe.json",
       "label_probe_candidate.npy", "position_period.json", ".metrics.csv.abc123.tmp",
       "checkpoints/latest.json", "mphi_data/added_000003.npz", "mphi_data_rival/added_000003.npz",
       "trajectories/gen_000000/members_0000-0007.parquet", "tb/events.out.tfevents.1.vm.2.0",
       "figures/reward.png", "videos/gen_000004.gif", "figures/.reward.png.k2j4.tmp",
       "trajectories/gen_000000/.members_0000-0007.parquet.abc.tmp"]


def _make(root, names):
    for n in names:
        (root / n).parent.mkdir(parents=True, exist_ok=True)
        (root / n).write_bytes(b"x")


def test_a_runs_own_files_are_replaced_whole(tmp_path):
    run = tmp_path / "r"
    _make(run, RUN)
    assert foreign_entries(run) == []
    replace_run_dir(run)
    assert not run.exists()


@pytest.mark.parametrize("extra", ["notes.txt", "checkpoints/gen_000002_backup.npz", "trajectories/gen_000000/mine.txt",
                                   "trajectories/keep/a.parquet", "figures/plot.pdf", "data/x.csv",
                                   # names close to a run's (an auditor's): another figure, a folder that only
                                   # looks like M_phi's data, a hidden .tmp of no name the run writes
                                   "figures/my_plot.png", "mphi_data_backup/added_000001.npz", ".mine.x.tmp",
                                   "checkpoints/.notes.txt.abc.tmp"])
def test_anything_else_refuses_with_nothing_deleted(tmp_path, extra):
    run = tmp_path / "r"
    _make(run, RUN + [extra])
    before = sorted(run.rglob("*"))
    with pytest.raises(StoreError, match="files no run writes"):
        replace_run_dir(run)
    assert sorted(run.rglob("*")) == before


def test_a_symlink_is_foreign_and_never_followed(tmp_path):
    run, outside = tmp_path / "r", tmp_path / "outside"
    _make(run, RUN)
    _make(outside, ["precious.txt"])
    (run / "figures" / "link").symlink_to(outside, target_is_directory=True)
    assert foreign_entries(run) == [run / "figures" / "link"]
    with pytest.raises(StoreError, match=r"\(figures/link\)"):
        replace_run_dir(run)
    assert (outside / "precious.txt").exists()
