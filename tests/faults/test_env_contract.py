"""An env that breaks the contract is named where its value enters, in one line (a real process each):
the old Gym API, a reward that is a string or an array, a dict observation, ``sys.exit`` in ``step``
(inline and in a worker process: before, ``sys.exit(0)`` ended the run with exit 0), and for the shaped
method ``info['position']`` / ``info['waypoint']`` non-finite, missing from step 3 or of different
sizes (before: M_phi's weights turned NaN and the env was blamed for a non-finite reward; or a
broadcast error). No checkpoint ever holds a non-finite array, the guide's included, and resume names
the checkpoint to fall back to. ``env.close()`` raising is one warning line."""

from __future__ import annotations

import numpy as np
import pytest
from fault_run import config, edit_npz, one_error_line, run_cli, write_config

from shaped_es.cli.commands import main

TINY = ["--executor", "inline", "--generations", "2", "--pairs", "2", "--set", "rollout.episodes=1", "--set",
        "rollout.test_episodes=1", "--set", "policy.hidden=[4]", "--set", "tensorboard=false", "--quiet"]
SHAPED = ["--method", "shaped", "--set", "shaping.inverse_dynamics.steps_per_generation=20", "--set",
          "shaping.cloning.steps=3"]


def faulty(fault, *extra):
    return ["--env", "fault_envs:Faulty-v0", *TINY, "--set", f"env_kwargs.fault={fault}", *extra]


def reach(fault):
    return ["--env", "fault_envs:Reach-v0", *TINY, *SHAPED, "--set", f"env_kwargs.fault={fault}"]


CASES = [
    # id, train arguments, needle
    ("string-reward", faulty("string_reward"), "a reward that is a str ('1e6')"),
    ("array-reward", faulty("array_reward"), "a reward that is an array of shape (3,)"),
    ("old-gym-step", faulty("old_step"), "a 4-tuple from step (obs, reward, done, info: the old Gym API)"),
    ("old-gym-reset", faulty("old_reset"), "an array of shape (3,) from reset instead of (observation, info)"),
    ("dict-obs-mid-episode", faulty("dict_obs"), "an observation that is a dict, not an array of shape (3,)"),
    ("sys-exit-0-inline", faulty("sys_exit0"), "called sys.exit(0) during a rollout"),
    ("sys-exit-0-process", faulty("sys_exit0", "--executor", "process", "--workers", "2"),
     "called sys.exit(0) during a rollout"),
    ("sys-exit-message", faulty("sys_exit_msg"), "called sys.exit('the simulator quit')"),
    ("nan-position", reach("nan_position"), "a non-finite info['position']"),
    ("inf-waypoint", reach("inf_waypoint"), "a non-finite info['waypoint']"),
    ("position-missing-from-step-3", reach("position_missing"), "no info['position']"),
    ("waypoint-position-dims-differ", reach("waypoint_3d"), "info['waypoint'] of size 3 and info['position'] of "
                                                            "size 2"),
]


@pytest.mark.parametrize("argv, needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_broken_contract_is_one_line_naming_it(tmp_path, argv, needle):
    res = run_cli("train", *argv, "--out", tmp_path / "run", timeout=120)
    assert res.returncode == 2, res.stderr
    line = one_error_line(res.stderr)
    assert needle in line, line
    if "step" in line and "reset(seed=0)" not in line:
        assert "episode seed" in line and "step " in line


def test_close_raising_is_one_warning_line(tmp_path):
    res = run_cli("train", *faulty("close_raises"), "--out", tmp_path / "run")
    assert res.returncode == 0, res.stderr
    lines = res.stderr.strip().splitlines()
    assert lines and all(ln.startswith("shaped-es: warning: env 'fault_envs:Faulty-v0' raised RuntimeError") and
                         "in close()" in ln for ln in lines), res.stderr


def test_check_env_names_dims_that_differ(faults_path):
    from shaped_es.cli.check_env import check_env

    checks = {c.name: c for c in check_env("fault_envs:Reach-v0", {"fault": "waypoint_3d"})}
    # "no" for shaped (the only method that reads them), not a FAIL for every method
    assert checks["waypoints"].status == "no" and "one d" in checks["waypoints"].detail


def test_no_checkpoint_holds_a_non_finite_guide_array_and_resume_names_the_fallback(tmp_path, faults_path):
    cfg = write_config(tmp_path / "c.yaml", config("shaped", generations=3, checkpoint_every=1))
    run = tmp_path / "run"
    # the healthy run that is then damaged trains in this process (faults_path: fault_envs imports here);
    # the resume under test is a process of its own
    assert main(["train", "--config", str(cfg), "--out", str(run), "--quiet"]) == 0
    key = "guide/mphi/net/flat"
    edit_npz(lambda a: {**a, key: np.full_like(a[key], np.nan)})(run, tmp_path)  # bound, digest matching
    res = run_cli("resume", run, "--generations", 4, "--quiet")
    assert res.returncode == 2
    line = one_error_line(res.stderr)
    assert f"{key} holds non-finite values" in line and "to resume from gen_000002" in line, line


def test_a_reward_that_is_an_array_of_one_trains_shaped_and_renders(tmp_path, faults_path):
    """A new user's simulator returned each reward as an array of shape (1,): the rollouts took it, while the
    label probe, ``render`` and PPO's test episodes called ``float`` on it (an internal TypeError) and check-env
    called it "not a finite number". Every path now reads a reward by the rollouts' rule (``env_probe.reward``)."""
    from shaped_es.cli.check_env import check_env

    run = tmp_path / "run"
    argv = ["train", *reach("reward_array1"), "--out", str(run)]
    assert main(argv) == 0
    import warnings

    with warnings.catch_warnings(record=True) as again:
        warnings.simplefilter("always")
        listed = check_env("fault_envs:Reach-v0", {"fault": "reward_array1"})
    checks = {c.name: c for c in listed}
    assert checks["steps"].status == "ok", checks["steps"]
    # Gymnasium's warning about it is the API line, and is not counted again from check-env's own episodes
    api = [c.detail for c in listed if c.name == "gymnasium API"]
    assert any("reward returned by `step()`" in d for d in api), api
    assert not any("reward returned by `step()`" in str(w.message) for w in again), [str(w.message) for w in again]
    assert main(["render", str(run), "--out", str(tmp_path / "r.gif")]) == 0
