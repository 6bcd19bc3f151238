"""A rollout map on the MPI executor, run as its own process (MPI initializes once per process).

``python mpi_job.py`` (spawn mode) or ``mpiexec -n 3 python -m mpi4py.futures mpi_job.py`` prints one
JSON line ``{"workers": w, "returns": [...], "lengths": [...]}``; exit code 3 means MPI could not start.
"""

from __future__ import annotations

import json
import sys

import numpy as np

from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask

CANNOT_START = 3


def make_tasks(chunks: int = 4) -> list[RolloutTask]:
    """CartPole rollouts of 8 random members (2 episodes each), split into ``chunks`` tasks."""
    spec = MLPSpec(4, 2, (8,))
    rng = np.random.default_rng(7)
    params = (np.stack([spec.init(i) for i in range(8)]) + rng.normal(0, 0.5, (8, spec.num_params))).astype(
        np.float32
    )  # (8, n)
    seeds = rng.integers(0, 2**31, (8, 2))  # (8, E=2)
    return [
        RolloutTask("CartPole-v1", {}, spec, params[idx], idx, seeds[idx], generation=0)
        for idx in np.array_split(np.arange(8), chunks)
    ]


def summarize(results) -> dict:
    return {
        "returns": np.concatenate([r.returns for r in results]).tolist(),  # (8, E)
        "lengths": np.concatenate([r.lengths for r in results]).tolist(),
    }


def main() -> int:
    from shaped_es.executors import ExecutorError
    from shaped_es.executors.mpi_executor import MPIExecutor
    from shaped_es.rollout import run_task

    try:
        ex = MPIExecutor(workers=2, startup_timeout_s=90)
    except ExecutorError as exc:
        print(f"MPI cannot start: {exc}", file=sys.stderr)
        return CANNOT_START
    try:
        out = {"workers": ex.workers, **summarize(ex.map(run_task, make_tasks()))}
    finally:
        ex.shutdown()
    print(json.dumps(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
