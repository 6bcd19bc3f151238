"""How the benchmark's page (``markdown.py``) and its verdict lines (``verdict.py``) print numbers."""

from __future__ import annotations

import math


def num(v, digits: int = 2) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "–"
    if isinstance(v, float) and digits == 0:
        return f"{v:,.0f}"
    return f"{v:.{digits}f}" if isinstance(v, float) else str(v)


def interval(ci, digits: int = 2) -> str:
    return f"[{num(ci[0], digits)}, {num(ci[1], digits)}]" if ci else "–"


def ratio_text(d: dict) -> str:
    """``0.50x [0.31, 0.78]``: a ``ratio_of_means`` result (``n/a`` without a ratio); the report's cells and the
    benchmark's verdict lines."""
    return f"{num(d['ratio'])}x {interval(d['ci'])}" if d.get("ratio") is not None else "n/a"
