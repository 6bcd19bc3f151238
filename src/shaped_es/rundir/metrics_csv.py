"""``RUN/metrics.csv``: one row per generation, the same columns for every method (``RunStore`` is the
way in; it checks the lock before any write).

Reading validates the whole file (a header starting with ``generation``, numbers only, generations in
increasing order) and leaves out a torn last line (no newline: a write a kill cut short); anything else
malformed is one-line ``StoreError``. :func:`rows_up_to` is what ``resume`` keeps: the rows a checkpoint
covers, with the duplicated rows two writers interleaved (a run written twice at once) reduced to the
last of each generation.
"""

from __future__ import annotations

import csv
import io
import math
import os
from pathlib import Path
from typing import Any

import numpy as np

from shaped_es.rundir.atomic import StoreError, atomic_write_text, check_regular, open_append, read_regular

_NON_FLOAT = ("", "True", "False")  # empty: no value (None or NaN); booleans as csv writes them
Table = tuple[list[str], list[dict[str, str]]]  # (header, rows)


def read_table(path: Path, repeats_ok: bool = False) -> Table:
    """(header, complete rows) of the file; ``repeats_ok``: generations may repeat or go back (rows of
    two writers, for :func:`rows_up_to` to repair) instead of being an error."""
    if not path.exists():
        return [], []
    try:
        text = read_regular(path).decode("utf-8")
    except UnicodeDecodeError:
        raise StoreError(f"{path} is not a CSV text file (binary content)") from None
    except OSError as exc:
        raise StoreError(f"cannot read {path}: {exc.strerror or exc}") from None
    if "\x00" in text:
        raise StoreError(f"{path} is not a CSV text file (binary content)")
    lines = text.splitlines(keepends=True)
    if lines and not lines[-1].endswith(("\n", "\r")):
        lines = lines[:-1]  # torn last row
    if not lines:
        return [], []
    try:
        table = list(csv.reader(lines))
    except csv.Error as exc:
        raise StoreError(f"{path} is not valid CSV: {exc}") from None
    header, body = table[0], table[1:]
    if not header or header[0] != "generation" or len(set(header)) != len(header):
        raise StoreError(f"{path} has no valid header (its first column must be 'generation')")
    rows, last = [], -1
    for i, cells in enumerate(body, start=2):
        if not cells:
            continue
        if len(cells) != len(header):
            raise StoreError(f"{path} line {i} has {len(cells)} fields, the header has {len(header)}")
        try:
            g = int(cells[0])
            for c in cells[1:]:
                if c not in _NON_FLOAT:
                    float(c)
        except ValueError:
            raise StoreError(f"{path} line {i} holds a non-numeric value") from None
        if g <= last and not repeats_ok:
            raise StoreError(f"{path} line {i}: generation {g} does not follow generation {last} (two "
                             f"writers? 'shaped-es resume' keeps the last row of each generation)")
        last = g
        rows.append(dict(zip(header, cells)))
    return header, rows


def append_row(path: Path, row: dict[str, Any]) -> None:
    """Append one row (fsynced); the first row fixes the header (later rows may not add columns)."""
    check_regular(path)
    new = not path.is_file() or path.stat().st_size == 0
    if new:
        fields = list(row)
    else:
        fields = next(csv.reader(io.StringIO(read_regular(path).decode("utf-8"), newline="")))
        extra = set(row) - set(fields)
        if extra:
            raise StoreError(f"metrics row has columns not in {path}: {sorted(extra)}")
    with open_append(path, newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        if new:
            w.writeheader()
        w.writerow({k: _fmt(row.get(k)) for k in fields})
        fh.flush()
        os.fsync(fh.fileno())


def rows_up_to(path: Path, last_generation: int) -> tuple[list[str], list[dict[str, str]], int]:
    """(header, rows, repeats): the rows of generations up to ``last_generation``, one per generation
    (the last written of each), in order, and how many repeated rows were left out."""
    header, rows = read_table(path, repeats_ok=True)
    newest = {int(r["generation"]): r for r in rows if int(r["generation"]) <= last_generation}
    kept = sum(int(r["generation"]) <= last_generation for r in rows)
    return header, [newest[g] for g in sorted(newest)], kept - len(newest)


def write_rows(path: Path, header: list[str], rows: list[dict[str, str]]) -> bool:
    """Make the file hold exactly ``header`` and ``rows`` (atomically; untouched if it already does, or
    if it is absent and there is nothing to hold); True if it was written."""
    buf = io.StringIO()
    if header:
        w = csv.DictWriter(buf, fieldnames=header)  # "\r\n", as append_row writes
        w.writeheader()
        w.writerows(rows)
    if not path.exists() or buf.getvalue().encode() == read_regular(path):
        return False
    atomic_write_text(path, buf.getvalue())
    return True


def _fmt(v: Any) -> Any:
    if v is None:
        return ""
    if isinstance(v, (float, np.floating)):
        f = float(v)
        return "" if math.isnan(f) else repr(f)
    if isinstance(v, np.integer):
        return int(v)
    return v
