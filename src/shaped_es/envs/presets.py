"""A built-in env's config from a named preset plus keyword overrides (``gymnasium.make`` kwargs)."""

from __future__ import annotations

from dataclasses import fields, replace
from typing import Any, TypeVar

C = TypeVar("C")


def preset_config(env_id: str, presets: dict[str, C], preset: str, overrides: dict[str, Any]) -> C:
    """``presets[preset]`` with ``overrides`` applied (lists become tuples) and validated; one-line
    ``ValueError`` naming ``env_id`` on an unknown preset or option."""
    if preset not in presets:
        raise ValueError(f"{env_id}: unknown preset {preset!r}; choose one of {sorted(presets)}")
    names = {f.name for f in fields(presets[preset])}
    unknown = sorted(set(overrides) - names)
    if unknown:
        raise ValueError(f"{env_id}: unknown option(s) {unknown}; valid: {sorted(names)}")
    clean = {k: tuple(v) if isinstance(v, list) else v for k, v in overrides.items()}
    return replace(presets[preset], **clean).validate()
