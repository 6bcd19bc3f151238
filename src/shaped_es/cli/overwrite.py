"""What ``report`` and ``render`` refuse to write over: files they did not write (a user's own page or
picture), and a report page of other runs. ``--force`` writes over them. One ``ConfigError`` line each."""

from __future__ import annotations

import json
from pathlib import Path

from shaped_es.benchmark.markdown import FIG4, FIG5, PROFILE, REPORT_MARK
from shaped_es.config import ConfigError


def _report_runs(out: Path) -> tuple[set[Path], set[Path]] | None:
    """The runs an existing report page at ``out`` shows (its ``summary.json``), read from the page's folder
    and from the working one (pages before 2026-12 kept runs outside their folder as the command named them);
    None: not a report's."""
    try:
        page = out.read_text(errors="replace")
        summary = json.loads((out.parent / "summary.json").read_text())
        runs = [p for group in summary["runs"].values() for p in group]
        paths = {(out.parent / p).resolve() for p in runs}, {Path(p).resolve() for p in runs}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None
    old_page = page.startswith("# ") and "## Fig. 4" in page  # a page from before the mark
    return paths if REPORT_MARK in page[:400] or old_page else None


def check_report_page(out: Path, run_dirs: list[Path], force: bool) -> None:
    """Refuse to write a report page beside a report's files without its page (even with ``force``), over a
    file no report wrote, or over the report of other runs (a page of some of these runs is redrawn with all)."""
    beside = [out.parent / "summary.json", *(out.parent / "figures" / f for f in (FIG4, FIG5, PROFILE))]
    taken = [str(p) for p in beside if p.exists()]
    if taken and not out.exists():  # files a report page writes, but not from a report here
        raise ConfigError(f"--out {out} would overwrite {', '.join(taken)}, which no report {out.name} "
                          f"wrote; choose a directory of its own (or the existing report to redraw it)")
    if force or not out.exists():
        return
    shown = _report_runs(out)
    if shown is None:
        raise ConfigError(f"--out {out} exists and is not a report page shaped-es wrote (with its summary.json "
                          f"beside it); choose another path, or pass --force to write over it")
    new = {Path(d).resolve() for d in run_dirs}
    # the same runs, or more (a benchmark rerun on fewer methods or seeds drew a page of those only; its line
    # says to draw them all there): nothing the page showed is lost
    if not any(s <= new for s in shown):
        shown, n = shown[0], len(shown[0])
        raise ConfigError(f"--out {out} is the report of other runs ({n} run{'s' * (n != 1)}, {len(shown & new)} "
                          f"of them among these {len(new)}); choose another path, or pass --force to replace it")


def check_free(paths: list[Path], force: bool) -> None:
    """Refuse to write over existing files (figures, a GIF) unless ``force``."""
    taken = [str(p) for p in paths if p.exists()]
    if taken and not force:
        one = len(taken) == 1
        raise ConfigError(f"--out would write over {', '.join(taken)}, which exist{'s' * one}; choose another name, "
                          f"or pass --force to write over {'it' if one else 'them'}")
