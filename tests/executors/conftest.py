"""Shared set-up for the executor tests: a private, quiet environment for any Ray started here."""

import os
import shutil
import tempfile
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / "src"


@pytest.fixture(scope="module")
def ray_env():
    """Ray's processes inherit this environment: a private temp dir (no other Ray on the machine finds
    ours, and ours finds no other), no usage reports, and import paths for the package and the fault
    helpers (workers import task functions by module name)."""
    keys = ("RAY_TMPDIR", "RAY_USAGE_STATS_ENABLED", "PYTHONPATH", "RAY_ADDRESS")
    saved = {k: os.environ.get(k) for k in keys}
    tmp = tempfile.mkdtemp(prefix="ray", dir="/tmp")  # short: Ray's socket paths must fit 107 bytes
    path = [str(SRC), str(HERE)] + ([saved["PYTHONPATH"]] if saved["PYTHONPATH"] else [])
    os.environ.update(RAY_TMPDIR=tmp, RAY_USAGE_STATS_ENABLED="0", PYTHONPATH=os.pathsep.join(path))
    os.environ.pop("RAY_ADDRESS", None)
    try:
        yield tmp
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v
        shutil.rmtree(tmp, ignore_errors=True)
