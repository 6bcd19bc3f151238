"""report, render and benchmark never write over files they did not write (cli/overwrite.py,
benchmark/runner.py's check_own_folder): a user's own page, picture or folder, or the report of other runs,
is refused in one line and left byte for byte; ``--force`` writes over a page or a picture."""

import json

import pytest

from shaped_es.cli.commands import main
from test_cli_main import TINY, _one_error_line


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    runs = [str(root / f"r{i}") for i in range(2)]
    for i, r in enumerate(runs):
        assert main(["train", "--env", "CartPole-v1", *TINY, "--seed", str(i), "--out", r]) == 0
    return runs


def test_a_users_own_page_is_refused_and_force_writes_over_it(tmp_path, two_runs, capsys):
    page = tmp_path / "report.md"
    page.write_text("my notes\n")
    capsys.readouterr()
    assert main(["report", two_runs[0], "--out", str(page)]) == 2
    assert "is not a report page shaped-es wrote" in _one_error_line(capsys)
    assert page.read_text() == "my notes\n" and sorted(p.name for p in tmp_path.iterdir()) == ["report.md"]
    assert main(["report", two_runs[0], "--out", str(page), "--force"]) == 0
    assert "my notes" not in page.read_text()


def test_a_folder_as_the_report_out_is_refused_naming_its_page(tmp_path, two_runs, capsys):
    """A new user's ``report --out myrep2``: the line names the page to write instead (``myrep2/report.md``)."""
    capsys.readouterr()
    assert main(["report", two_runs[0], "--out", str(tmp_path / "myrep2")]) == 2
    line = _one_error_line(capsys)
    assert "got myrep2 (a report page: --out " in line and line.endswith(f"{tmp_path / 'myrep2' / 'report.md'})")
    assert main(["report", two_runs[0], "--out", str(tmp_path / "rep.txt")]) == 2
    assert _one_error_line(capsys).endswith(f"(a report page: --out {tmp_path / 'rep.md'})")
    assert sorted(tmp_path.iterdir()) == []


def test_the_same_runs_redraw_their_page_and_other_runs_are_refused(tmp_path, two_runs, capsys):
    page = tmp_path / "rep" / "report.md"
    assert main(["report", *two_runs, "--out", str(page)]) == 0
    assert main(["report", *two_runs, "--out", str(page)]) == 0  # a redraw of the same runs
    before = (page.read_text(), (page.parent / "summary.json").read_text())
    capsys.readouterr()
    assert main(["report", two_runs[0], "--out", str(page)]) == 2
    assert "is the report of other runs (2 runs, 1 of them among these 1)" in _one_error_line(capsys)
    assert (page.read_text(), (page.parent / "summary.json").read_text()) == before
    assert main(["report", two_runs[0], "--out", str(page), "--force"]) == 0
    assert len([p for g in json.loads((page.parent / "summary.json").read_text())["runs"].values() for p in g]) == 1
    # a page of some of these runs (a benchmark rerun on one seed drew it) is redrawn with all of them
    assert main(["report", *two_runs, "--out", str(page)]) == 0
    assert len([p for g in json.loads((page.parent / "summary.json").read_text())["runs"].values() for p in g]) == 2


def test_runs_named_from_the_working_folder_redraw_their_page(tmp_path, two_runs, monkeypatch):
    """A new user's `report bench/runs... --out combined/report.md`, run twice from the same folder: the second
    was refused as "the report of other runs" (the page kept the runs' paths as the command named them)."""
    import shutil

    for i, r in enumerate(two_runs):
        shutil.copytree(r, tmp_path / "bench" / "runs" / f"r{i}")
    monkeypatch.chdir(tmp_path)
    runs = ["bench/runs/r0", "bench/runs/r1"]
    assert main(["report", *runs, "--out", "combined/report.md"]) == 0
    assert main(["report", *runs, "--out", "combined/report.md"]) == 0
    stored = json.loads((tmp_path / "combined" / "summary.json").read_text())["runs"]
    assert sorted(p for g in stored.values() for p in g) == ["../bench/runs/r0", "../bench/runs/r1"]  # from the page
    monkeypatch.chdir(tmp_path / "combined")  # and from another folder
    assert main(["report", "../bench/runs/r0", "../bench/runs/r1", "--out", "report.md"]) == 0


def test_existing_pictures_are_refused(tmp_path, two_runs, capsys):
    photo = tmp_path / "photo.png"
    photo.write_bytes(b"mine")
    capsys.readouterr()
    assert main(["report", two_runs[0], "--out", str(photo)]) == 2
    assert "would write over" in _one_error_line(capsys) and photo.read_bytes() == b"mine"
    gif = tmp_path / "mine.gif"
    gif.write_bytes(b"mine")
    assert main(["render", two_runs[0], "--out", str(gif)]) == 2
    assert "pass --force" in _one_error_line(capsys) and gif.read_bytes() == b"mine"


def test_benchmark_refuses_a_folder_of_other_files(tmp_path, capsys):
    folder = tmp_path / "paper"
    folder.mkdir()
    (folder / "report.md").write_text("mine")
    capsys.readouterr()
    assert main(["benchmark", "--env", "CartPole-v1", "--methods", "vanilla", "--seeds", "1", "--generations", "1",
                 "--out", str(folder), "--quiet", "--no-estimate"]) == 2
    assert "holds no benchmark but other files (report.md)" in _one_error_line(capsys)
    assert sorted(p.name for p in folder.iterdir()) == ["report.md"] and (folder / "report.md").read_text() == "mine"


def test_a_reports_files_without_its_page_are_refused_even_with_force(tmp_path, two_runs, capsys):
    (tmp_path / "summary.json").write_text("{}")
    capsys.readouterr()
    assert main(["report", two_runs[0], "--out", str(tmp_path / "report.md"), "--force"]) == 2
    assert "which no report report.md wrote" in _one_error_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["summary.json"]
