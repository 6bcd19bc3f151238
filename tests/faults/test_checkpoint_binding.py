"""A checkpoint proves whose it is: its arrays name the run and generation they were saved for and its
``.json`` holds their sha256, so a ``.npz`` from elsewhere -- the same generation of another seed's run,
this run's older generation renamed, an edited file -- is refused by ``resume`` and ``evaluate`` in one
line naming the checkpoint to fall back to, and nothing changes (before: both went on, exit 0, with the
other arrays)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from fault_run import newest, one_error_line, run_cli, snapshot

from shaped_es.rundir.store import BIND_PREFIX, RunStore, StoreError

TINY = ["--env", "Pendulum-v1", "--method", "vanilla", "--generations", "3", "--pairs", "2", "--executor",
        "inline", "--set", "rollout.test_episodes=1", "--set", "tensorboard=false", "--set",
        "policy.hidden=[4]", "--quiet"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("bind")
    for seed in (1, 2):
        res = run_cli("train", *TINY, "--seed", seed, "--out", root / f"s{seed}")
        assert res.returncode == 0, res.stderr
    return root


def other_seeds_file(run, other):
    shutil.copy(newest(other, ".npz"), newest(run, ".npz"))


def older_renamed(run, other):
    shutil.copy(run / "checkpoints" / "gen_000002.npz", newest(run, ".npz"))


def edited(run, other):
    p = newest(run, ".npz")
    with np.load(p) as z:
        arrays = {k: z[k] for k in z.files}
    arrays["policy/best"] = arrays["policy/best"] * 2
    with open(p, "wb") as fh:
        np.savez(fh, **arrays)


CASES = [("other-seeds-npz", other_seeds_file, "holds the arrays of another run"),
         ("older-generation-renamed", older_renamed, "holds generation 2's arrays, not generation 3's"),
         ("arrays-edited", edited, "sha256 differs")]


@pytest.mark.parametrize("command", ["resume", "evaluate"])
@pytest.mark.parametrize("damage, needle", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_checkpoint_from_elsewhere_is_refused(runs, tmp_path, damage, needle, command):
    run = tmp_path / "run"
    shutil.copytree(runs / "s1", run)
    damage(run, runs / "s2")
    before = snapshot(run)
    argv = ["resume", run, "--generations", 4, "--quiet"] if command == "resume" else \
        ["evaluate", run, "--episodes", 1]
    res = run_cli(*argv)
    assert res.returncode == 2, res.stderr
    line = one_error_line(res.stderr)
    assert needle in line and "gen_000003" in line and "to resume from gen_000002" in line, line
    assert snapshot(run) == before


def test_saved_arrays_are_bound_and_loaded_without_the_binding(tmp_path):
    store = RunStore(tmp_path / "r")
    store.root.mkdir()
    store.save_checkpoint(1, {"a": np.arange(3.0)}, {}, keep=2)
    with np.load(store.ckpt_dir / "gen_000001.npz") as z:
        assert sorted(z.files) == ["a", f"{BIND_PREFIX}generation", f"{BIND_PREFIX}run_id"]
    arrays, meta = store.load_checkpoint()
    assert list(arrays) == ["a"] and len(meta["arrays_sha256"]) == 64
    (store.ckpt_dir / "gen_000001.npz").write_bytes((store.ckpt_dir / "gen_000001.npz").read_bytes())
    store.save_checkpoint(2, {"a": np.arange(3.0)}, {}, keep=2)
    shutil.copy(store.ckpt_dir / "gen_000001.json", store.ckpt_dir / "gen_000002.json")
    with pytest.raises(StoreError, match="unreadable"):  # the .json names generation 1
        store.load_checkpoint()
