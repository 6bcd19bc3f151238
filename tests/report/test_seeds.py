"""A seed counts once in ``shaped-es report`` (issue 29): runs with the same method, settings and seed (a
copied run directory, a run trained again, one ``--stop-at`` ended beside the full one) are one seed, with
one warning line naming the copies; and each run that never reaches the threshold is censored at its own
budget, the shorter ones named in the report."""

import json
import shutil
import subprocess
import sys

from helpers import SRC
from report.test_grouping import make_run
from shaped_es.cli.commands import main
from shaped_es.report.seeds import distinct_seeds


def test_distinct_seeds_keeps_the_longest_run_of_each_seed():
    runs = [("a", 0, 5), ("b", 1, 3), ("c", 0, 7), ("d", 0, 7), ("e", 2, 1)]
    kept, copies = distinct_seeds(runs, lambda r: r[1], lambda r: r[2])
    assert [r[0] for r in kept] == ["c", "b", "e"]  # seed order of first appearance; c: longest, first of ties
    assert [(k[0], [c[0] for c in v]) for k, v in copies] == [("c", ["a", "d"])]


def _runs(tmp_path):
    full = make_run(tmp_path / "quickstart", "shaped", seed=0, tests=(1.0, 2.0, 3.0, 4.0, 5.0))
    copy = tmp_path / "quickstart2"
    shutil.copytree(full, copy)  # a copied run directory is no second seed
    stop = make_run(tmp_path / "stopat", "shaped", seed=0, tests=(1.0, 2.0), stop_at=2.0)
    other = make_run(tmp_path / "seed1", "shaped", seed=1, tests=(1.0, 1.0, 6.0, 6.0, 6.0))
    short = make_run(tmp_path / "vshort", "vanilla", seed=0, tests=(1.0, 1.0, 1.0))
    long = make_run(tmp_path / "vlong", "vanilla", seed=1, tests=(1.0,) * 8)
    return [full, copy, stop, other, short, long]


def test_report_counts_a_seed_once_and_censors_each_run_at_its_own_budget(tmp_path, capsys):
    dirs = _runs(tmp_path)
    out = tmp_path / "rep" / "report.md"
    assert main(["report", *map(str, dirs), "--threshold", "5.5", "--out", str(out)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    verdicts = [ln for ln in err if ln.startswith("[report] ")]  # the benchmark's verdict lines, against vanilla
    assert [v.split(":")[0] for v in verdicts] == ["[report] shaped vs vanilla"]
    err = [ln for ln in err if ln not in verdicts]
    assert len(err) == 1 and err[0].startswith("shaped-es: warning: 2 'shaped' runs repeat another's method, "
                                               "settings and seed, so each seed counts once")
    assert f"{dirs[1]}, {dirs[2]} as {dirs[0]} (seed 0)" in err[0]
    s = json.loads((out.parent / "summary.json").read_text())
    shaped, vanilla = s["methods"]["shaped"], s["methods"]["vanilla"]
    assert shaped["seeds"] == 2 and s["runs"]["shaped"] == ["../quickstart", "../seed1"]  # from the page
    assert shaped["to_threshold"]["generations"]["per_seed"] == [6.0, 3.0]  # seed 0 censored at 5 + 1
    # the 3-generation run is censored at 3 + 1, not at the 8-generation run's 9
    assert vanilla["to_threshold"]["generations"]["per_seed"] == [4.0, 9.0]
    assert vanilla["to_threshold"]["budgets"] == [3, 8] and s["budget_generations"] == 8
    md = " ".join(out.read_text().split())
    assert (f"Runs that never reached the threshold in fewer generations than the longest run (8), each censored "
            f"at its own budget + 1, not at 9: `../quickstart` (5 generations), `../vshort` (3 generations).") in md
    assert ("Runs of different lengths: shaped 5 generations, vanilla 3-8: the final rewards below are each run's "
            "last at its own length.") in md


def test_report_of_copies_as_a_process(tmp_path):
    dirs = _runs(tmp_path)[:3]
    res = subprocess.run([sys.executable, "-m", "shaped_es.cli.commands", "report", *map(str, dirs),
                          "--out", str(tmp_path / "rep" / "report.md")], capture_output=True, text=True,
                         env={"PYTHONPATH": str(SRC), "PATH": "/usr/bin:/bin", "MPLBACKEND": "Agg"}, timeout=300)
    assert res.returncode == 0, res.stderr
    (line,) = res.stderr.strip().splitlines()
    assert line.startswith("shaped-es: warning: 2 'shaped' runs repeat another's")
    assert json.loads((tmp_path / "rep" / "summary.json").read_text())["methods"]["shaped"]["seeds"] == 1
