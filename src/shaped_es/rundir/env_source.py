"""Which version of a user's env a run was made with: the SHA-256 of the env module's source file, kept in the
run's ``run.json`` when the run is created, so that a benchmark rerun or a resume on an edited env says so.

A run directory stores the env's id (``module:Env-v0``), not its code (README, "Your own env": its code is
imported, not saved): after editing ``myrobot.py``, a benchmark rerun into the same ``--out`` would reuse every
finished run, made on the old env, beside new ones made on the new (a new user expected it to redo them). The
fingerprint is the file the id names (``module``'s own file, found without importing it); code it imports from
elsewhere is not covered. Built-in envs (no ``module:`` prefix, or ``shaped_es``'s own) have none.
"""

from __future__ import annotations

import hashlib
import importlib.util
from pathlib import Path


def fingerprint(env_id: str) -> dict | None:
    """``{"module": name, "file": path, "sha256": hex}`` of the module a ``module:Env-v0`` id names (None: a
    built-in or registered id, a module without a source file, or one that cannot be read)."""
    module, sep, _ = env_id.partition(":")
    if not sep or not module or module.split(".")[0] == "shaped_es":
        return None
    try:
        spec = importlib.util.find_spec(module)
    except (ImportError, ValueError):  # a parent package that cannot be imported: no fingerprint
        return None
    origin = getattr(spec, "origin", None) if spec is not None else None
    if not origin or not origin.endswith(".py"):
        return None
    try:
        digest = hashlib.sha256(Path(origin).read_bytes()).hexdigest()
    except OSError:
        return None
    return {"module": module, "file": str(Path(origin).resolve()), "sha256": digest}


def changed(recorded: dict | None, now: dict | None) -> str | None:
    """The module's file name if its source now (``now``: :func:`fingerprint`'s) differs from ``recorded`` (a run's
    ``run.json`` ``env_source``); None when it is the same, or either side has none (a run made before fingerprints,
    a built-in env)."""
    if not (isinstance(recorded, dict) and now) or recorded.get("module") != now["module"]:
        return None
    return Path(now["file"]).name if recorded.get("sha256") != now["sha256"] else None
