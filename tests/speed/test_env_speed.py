"""``shaped-es speed env``: an env with a batched core and one without (plain Gymnasium stepping) are both
measured; a worker's failure is one error line, never a hang."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from shaped_es.speed.env_speed import BATCHED_LOOP, GYM_LOOP, bench_env

FAULTS = Path(__file__).resolve().parents[1] / "faults"
QUICK = {"num_envs": 4, "seconds": 0.2, "warmup_s": 0.05, "repeats": 2}


def test_an_env_without_a_batched_core_is_measured_by_stepping_gymnasium_envs():
    res = bench_env("Pendulum-v1", workers=1, **QUICK)  # Gymnasium's own env: no env.unwrapped.batch_core
    assert res["loop"] == GYM_LOOP and res["num_envs"] == 4 and res["steps_per_second"] > 0
    json.dumps(res)


def test_a_builtin_env_is_measured_on_its_batched_core():
    res = bench_env("CarNav-v0", workers=1, **QUICK)
    assert res["loop"] == BATCHED_LOOP and res["steps_per_second"] > 0


@pytest.mark.timeout(180)
def test_the_command_ends_with_worker_processes_on_an_env_without_a_batched_core():
    # it printed "has no batched core" once per worker and hung in pool.map (SIGTERM did not end it)
    cmd = [sys.executable, "-m", "shaped_es.cli.commands", "speed", "env", "Pendulum-v1", "--workers", "2",
           "--num-envs", "4", "--seconds", "0.5", "--json"]
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        out, err = p.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)  # its own session: the command and its workers
        p.communicate()
        pytest.fail("shaped-es speed env hung")
    assert p.returncode == 0, err
    res = json.loads(out)
    assert res["loop"] == GYM_LOOP and res["workers"] == 2 and len(res["per_worker_steps_per_second"]) == 2


@pytest.mark.timeout(180)
def test_an_env_that_exits_in_a_worker_is_one_error_not_a_hang(monkeypatch):
    from shaped_es.env_probe import EnvError

    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(FAULTS), os.environ.get("PYTHONPATH", "")]))
    monkeypatch.syspath_prepend(str(FAULTS))
    with pytest.raises(EnvError, match=r"called sys\.exit\('the simulator quit'\) while its speed was measured"):
        bench_env("fault_envs:Faulty-v0", workers=2, env_kwargs={"fault": "sys_exit_msg"}, **QUICK)
