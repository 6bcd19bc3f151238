"""Reading a config's text: YAML files and ``--set KEY=VALUE`` flags, as plain data (safe: no objects,
bounded aliases), each failure one :class:`ConfigError` line naming the file or flag. What the data means
is ``config.py``'s (the typed sections, validation, defaults)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from shaped_es import safe_yaml


class ConfigError(ValueError):
    """A config file or flag is malformed; the message is one line naming the field."""


def parse_yaml(text: str, where: str) -> Any:
    """``text`` read as YAML (safe: plain data only, bounded aliases); ``ConfigError`` naming ``where``
    (``config file X``, ``--set K=V``) if it cannot be read."""
    try:
        return safe_yaml.load(text)
    except yaml.YAMLError as exc:
        line = getattr(getattr(exc, "problem_mark", None), "line", None)
        at = f" (line {line + 1})" if line is not None else ""
        raise ConfigError(f"{where} is not valid YAML{at}") from None
    except safe_yaml.AliasError as exc:
        raise ConfigError(f"{where}: {exc}") from None
    except RecursionError:
        raise ConfigError(f"{where} nests too deeply to be a config") from None
    except (ValueError, TypeError, OverflowError) as exc:  # e.g. an impossible date; an alias bomb
        raise ConfigError(f"{where} holds a value YAML cannot read: {str(exc).splitlines()[0]}") from None


def read_yaml(path: str | Path) -> dict[str, Any]:
    p = Path(path)
    if p.is_dir():
        raise ConfigError(f"config file {p} is a folder, not a YAML file")
    if not p.exists():  # a pipe (--config /dev/stdin, <(...)) is read like a file
        raise ConfigError(f"config file not found: {p}")
    try:
        text = p.read_bytes().decode("utf-8")
    except UnicodeDecodeError:
        raise ConfigError(f"config file {p} is not a text (UTF-8) file") from None
    except OSError as exc:
        raise ConfigError(f"cannot read config file {p}: {exc.strerror or exc}") from None
    data = parse_yaml(text, f"config file {p}")
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise ConfigError(f"config file {p} must hold a mapping of fields, got {type(data).__name__}")
    return data


def set_item(text: str) -> str:
    """``--set``'s argparse type: ``KEY=VALUE`` as one word (``--set es.sigma 0.1`` is refused here,
    naming the fix, before argparse would report the value as an unrecognized argument)."""
    if "=" not in text:
        import argparse

        raise argparse.ArgumentTypeError(f"expects KEY=VALUE as one word, got {text!r}: write --set "
                                         f"{text or 'es.sigma'}=VALUE, no spaces around '='")
    return text


def parse_set(items: list[str] | None) -> dict[str, Any]:
    """``--set KEY=VALUE`` flags as overrides for :func:`merge` (each value read as YAML). An empty value is
    refused like any bad value, ``(got '')``: YAML reads it as null, which left an optional field unset without
    a word (an empty shell variable: ``--set rollout.max_steps=$STEPS``) and named no value where it failed."""
    out = {}
    for item in items or []:
        if "=" not in item:
            raise ConfigError(f"--set expects KEY=VALUE, got {item!r}")
        k, v = item.split("=", 1)
        if not v.strip():
            raise ConfigError(f"invalid config: {k.strip()}: an empty value; give one (null leaves an optional "
                              f"field unset) (got {v!r})")
        out[k.strip()] = parse_yaml(v, f"--set {item}")
    return out
