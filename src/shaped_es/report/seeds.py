"""One seed counts once: runs of the same method and settings with the same root seed are one experiment
run twice (a copied run directory, a run trained again into another folder, a run ``--stop-at`` ended
early beside the full one), not two seeds. A run is reproducible from its seed (DESIGN.md,
"Determinism"), so such runs hold the same curve, one perhaps longer than the other; counting both would
shrink every confidence interval and tilt every mean toward that seed.

:func:`distinct_seeds` keeps one run per seed (the one with the most generations, the first given on a
tie) and names the others as its copies; the report says so in one warning line (``group_runs`` in
``benchmark/summary.py`` calls it on every group of runs sharing a method and its settings).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable, Hashable, Sequence, TypeVar

T = TypeVar("T")


def distinct_seeds(runs: Sequence[T], seed_of: Callable[[T], Hashable],
                   length_of: Callable[[T], int]) -> tuple[list[T], list[tuple[T, list[T]]]]:
    """``(kept, copies)``: one run per seed, in the order the seeds first appear (the run of that seed with
    the most generations, ``length_of``; the first given on a tie), and ``(kept run, the runs it stands
    for)`` for each kept run that had copies."""
    by_seed: dict[Hashable, list[T]] = {}
    for run in runs:
        by_seed.setdefault(seed_of(run), []).append(run)
    kept, copies = [], []
    for same in by_seed.values():
        best = max(same, key=length_of)  # max keeps the first of equal lengths
        kept.append(best)
        if len(same) > 1:
            copies.append((best, [r for r in same if r is not best]))
    return kept, copies


def copies_line(label: str, seed_of: Callable, copies: list) -> str:
    """The warning line for ``copies`` of the group ``label``: which runs count as which one, and why."""
    parts = "; ".join(f"{', '.join(str(_path(c)) for c in cs)} as {_path(k)} (seed {seed_of(k)})"
                      for k, cs in copies)
    n = sum(len(cs) for _, cs in copies)
    return (f"{n} {label!r} run{'s' * (n > 1)} repeat{'s' * (n == 1)} another's method, settings and seed, so "
            f"each seed counts once (the run with the most generations): {parts}")


def _path(run) -> Path:
    return run[0] if isinstance(run, tuple) else run
