"""A check-env check's record (:class:`Check`: what is checked, its status, one line), the four statuses
(``ok``, ``no``, ``warn``, ``FAIL``; ``check_env.py``'s docstring says what each means), and what a list of
checks comes to: the methods the env trains with (:func:`trains_with`) and the JSON form (:func:`as_dicts`)."""

from __future__ import annotations

from dataclasses import asdict, dataclass

OK, NO, WARN, FAIL = "ok", "no", "warn", "FAIL"


@dataclass(frozen=True)
class Check:
    name: str  # what is checked, e.g. "spaces"
    status: str  # OK / NO / WARN / FAIL
    detail: str  # one line


def trains_with(checks: list[Check]) -> list[str]:
    """The methods the env trains with, given its checks (none if one failed)."""
    from shaped_es.methods import METHODS

    by = {c.name: c.status for c in checks}
    if FAIL in by.values():
        return []
    return [m for m, method in METHODS.items() if all(by.get(need) == OK for need in method.needs)]


def as_dicts(checks: list[Check]) -> list[dict]:
    return [asdict(c) for c in checks]
