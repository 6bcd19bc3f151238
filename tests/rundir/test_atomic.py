"""rundir/atomic.py: the stale temporaries of a folder without a lock (a benchmark's, a suite's)."""

import os
import time

from shaped_es.rundir.atomic import STALE_TMP_S, atomic_write_text, clean_stale_temporaries


def test_only_old_temporaries_of_the_names_given_are_deleted(tmp_path):
    old = time.time() - STALE_TMP_S - 60
    ours = tmp_path / ".report.md.k2j3_xq1.tmp"  # a killed writer's, left long ago
    fresh = tmp_path / ".report.md.zz9abc12.tmp"  # another process's, still writing
    other = [tmp_path / ".notes.md.k2j3_xq1.tmp", tmp_path / ".report.md.bak", tmp_path / "report.md.k2.tmp"]
    for p in [ours, fresh, *other]:
        p.write_text("x")
    for p in [ours, *other]:
        os.utime(p, (old, old))
    (tmp_path / ".summary.json.abc.tmp").mkdir()  # a folder of that name: not a temporary
    os.symlink(tmp_path / "report.md.k2.tmp", tmp_path / ".summary.json.lnk1.tmp")
    os.utime(tmp_path / ".summary.json.lnk1.tmp", (old, old), follow_symlinks=False)
    removed = clean_stale_temporaries(tmp_path, ("report.md", "summary.json"))
    assert removed == [ours]
    assert fresh.exists() and all(p.exists() for p in other)
    assert (tmp_path / ".summary.json.abc.tmp").is_dir() and (tmp_path / ".summary.json.lnk1.tmp").is_symlink()
    assert clean_stale_temporaries(tmp_path / "absent", ("report.md",)) == []


def test_a_write_leaves_no_temporary(tmp_path):
    atomic_write_text(tmp_path / "report.md", "# page\n")
    assert [p.name for p in tmp_path.iterdir()] == ["report.md"]
    assert clean_stale_temporaries(tmp_path, ("report.md",), older_than_s=-1) == []
