"""Fixtures of the fault-injection tests (their helpers are in fault_run.py)."""

from __future__ import annotations

import pytest
from fault_run import HERE, env


@pytest.fixture
def faults_path(monkeypatch):
    """Worker processes (and in-process runs) import fault_envs."""
    monkeypatch.setenv("PYTHONPATH", env()["PYTHONPATH"])
    monkeypatch.syspath_prepend(str(HERE))
    return HERE
