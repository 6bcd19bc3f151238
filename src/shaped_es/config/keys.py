"""The keys a user writes in a config: dotted keys (``es.sigma``) as paths into the sections, and the one
error line that names a misspelt key with the fields it may mean.

A dotted key names a field of a section in ``--set KEY=VALUE``, in the API's config dicts and at the top
level of a ``--config`` YAML file (``shaping.mean_clone.accept: paired``), all through :func:`merge`. A
misspelt key, at any depth and however it was written, gets the closest fields of its section
(``shaping.mean_clone.acept: unknown field (did you mean accept?)``).
"""

from __future__ import annotations

import difflib
from typing import Any

from pydantic import BaseModel, ValidationError


def merge(data: dict[str, Any], overrides: dict[str, Any]) -> dict[str, Any]:
    """``data`` with ``overrides`` applied, each value set at its key's path (``{"es.sigma": 0.1}`` sets
    ``sigma`` in ``es``). ``data``'s own dotted keys apply after its sections (``es: {pairs: 2}`` and
    ``es.sigma: 0.1`` in one file both hold, in either order); ``overrides`` after all of ``data``."""
    out = {k: (dict(v) if isinstance(v, dict) else v) for k, v in data.items() if not _dotted(k)}
    for key, value in [*((k, v) for k, v in data.items() if _dotted(k)), *overrides.items()]:
        node = out
        parts = key.split(".")
        for part in parts[:-1]:
            nxt = node.get(part)
            if not isinstance(nxt, dict):
                nxt = {}
            node[part] = nxt = dict(nxt)
            node = nxt
        node[parts[-1]] = value
    return out


def _dotted(key) -> bool:
    return isinstance(key, str) and "." in key


def first_error(exc: ValidationError, model: type[BaseModel] | None = None) -> str:
    """The first error of ``exc`` as one line naming its field (``es.sigma: ... (got 0)``); a misspelt key
    of ``model`` (the model validated) names the fields it may mean."""
    err = exc.errors()[0]
    where = ".".join(str(p) for p in err["loc"]) or "config"
    others = [".".join(str(p) for p in e["loc"]) or "config" for e in exc.errors()[1:]]  # named, to fix in one go
    more = f" (+{len(others)} more: {', '.join(others[:3])}{', ...' if len(others) > 3 else ''})" if others else ""
    msg = " ".join(str(err["msg"]).removeprefix("Value error, ").split())
    if err.get("type") == "extra_forbidden":  # a misspelt key: name the section's fields it may mean
        msg = "unknown field" + (did_you_mean(model, err["loc"]) if model is not None else "")
    elif err.get("type") == "bool_type":  # YAML 1.1's yes/no/on/off are words here (safe_yaml)
        msg = "Input should be a valid boolean, true or false"
    elif err.get("type") in ("tuple_type", "list_type"):  # the words `shaped-es config` uses for such a key
        msg = "Input should be a list" + (f", e.g. its default {_default_at(model, err['loc'])}" if model else "")
    value = err.get("input")
    got = ""
    if err.get("type") != "extra_forbidden" and "(" not in msg:
        if isinstance(value, (bool, int, float, str)):
            shown = str(value).lower() if isinstance(value, bool) else repr(value)
            got = f" (got {shown[:40]})"
        elif value is None and "input" in err:  # `key:` with nothing after it reads as null
            got = " (got null: `key: null`, or `key:` with nothing after it)"
    return f"{where}: {msg}{got}{more}"


def _default_at(model: type[BaseModel], loc: tuple) -> str:
    """The default of the field at ``loc`` as YAML writes a list (``[8, 16]``); ``'[]'`` if not found."""
    default = None
    for part in loc:
        field = getattr(model, "model_fields", {}).get(part)
        if field is None:
            break
        default, model = field.get_default(call_default_factory=True), field.annotation
    return "[" + ", ".join(str(v) for v in default) + "]" if isinstance(default, (list, tuple)) else "[]"


def did_you_mean(model: type[BaseModel], loc: tuple) -> str:
    """``' (did you mean ...?)'``: the fields closest to the unknown key at ``loc`` (a path from ``model``),
    from the fields of its section. A dotted key left inside a section (``shaping: {mean_clone.acept: x}``)
    is walked part by part: the first part no field matches gets the suggestion; if every part matches,
    the line says to nest it. ``''`` when nothing is close."""
    path = [*loc[:-1], *str(loc[-1]).split(".")]
    for part in path:
        fields = getattr(model, "model_fields", None)
        if fields is None:
            return ""
        if part not in fields:
            close = difflib.get_close_matches(str(part), list(fields), n=2, cutoff=0.6) or _deeper(model, str(part))
            return f" (did you mean {' or '.join(close)}?)" if close else ""
        model = fields[part].annotation  # a plain field has none: a dotted key past it gets no suggestion
    return " (a dotted key is not a path here: nest it, one key per level)"


def _deeper(model: type[BaseModel], name: str, prefix: str = "", depth: int = 3) -> list[str]:
    """Dotted paths below ``model``'s sections whose last field is ``name`` (``sigma`` -> ``es.sigma``): a key
    given at the wrong level (a new user's ``--set sigma=0.1``); at most two."""
    found: list[str] = []
    for key, field in getattr(model, "model_fields", {}).items():
        sub = field.annotation
        if depth and isinstance(sub, type) and issubclass(sub, BaseModel):
            if name in sub.model_fields:
                found.append(f"{prefix}{key}.{name}")
            found += _deeper(sub, name, f"{prefix}{key}.", depth - 1)
    return list(dict.fromkeys(found))[:2]
