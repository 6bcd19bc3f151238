"""The shaped method with the paper's mechanism end to end on UR5Reach-v0 (tiny budgets): alpha=1 is
Vanilla-ES, resume is exact, both placements of the shaping work give the same run. The other mechanisms:
test_mechanisms.py."""

import numpy as np
import pytest

from helpers import kill_after_rows, new_run, popen_cli, run_until_crash, strip_time, train
from shaped_es.config import ConfigError, build_config
from shaped_es.rundir.store import RunStore
from shaped_es.trainer import Trainer

TINY = {
    "env": "UR5Reach-v0",
    "executor": "inline",
    "generations": 4,
    "seed": 1,
    "es": {"pairs": 6},
    "policy": {"hidden": [8]},
    "rollout": {"episodes": 1, "test_episodes": 2, "max_steps": 40},
    "shaping": {"mechanism": "paper", "inverse_dynamics": {"steps_per_generation": 30, "min_return": -1e9},
                "cloning": {"steps": 5}, "history": 2},
    "tensorboard": False,
}


def _run(tmp_path, name, **over):
    return train(tmp_path / name, {**TINY, **over})


def _rewards(rows):
    return [(r["train_reward_mean"], r["train_reward_max"], r["test_reward_mean"]) for r in rows]


def test_alpha_one_reduces_to_vanilla(tmp_path):
    es = {**TINY["es"], "alpha": 1.0}
    shaped = _run(tmp_path, "shaped", method="shaped", es=es).read_metrics()
    vanilla = _run(tmp_path, "vanilla", method="vanilla", es=es).read_metrics()
    assert _rewards(shaped) == _rewards(vanilla)
    # ... while the shaped machinery really ran
    assert float(shaped[-1]["mphi_iterations"]) > 0 and int(shaped[-1]["surrogate_rank"]) > 0
    assert float(shaped[-1]["clone_loss_after"]) < float(shaped[-1]["clone_loss_before"])


def test_shaped_changes_search_and_resumes_exactly(tmp_path):
    full = _run(tmp_path, "full", method="shaped")
    vanilla = _run(tmp_path, "van", method="vanilla")
    assert _rewards(full.read_metrics())[2:] != _rewards(vanilla.read_metrics())[2:]
    part = _run(tmp_path, "part", method="shaped", generations=2)
    cfg = build_config({**TINY, "method": "shaped", "generations": 4})
    Trainer(cfg, part, progress=False).run()
    assert strip_time(part.read_metrics()) == strip_time(full.read_metrics())
    arrays, _ = full.load_checkpoint()
    assert "guide/mphi/data/x" not in arrays and (full.root / "mphi_data").is_dir()  # data set saved once

    def shards(store):
        return [int(p.name[4:]) for p in sorted((store.root / "trajectories").iterdir())]

    # pruned once the next checkpoint is on disk: what the last kept checkpoints' re-runs read
    # (history 2: g and g-history+2..g; keep_checkpoints 3 adds 2 generations of slack)
    assert shards(_run(tmp_path, "k1", method="shaped", generations=6, keep_checkpoints=1)) == [4, 5]
    assert shards(_run(tmp_path, "k3", method="shaped", generations=6)) == [2, 3, 4, 5]


def test_trajectories_on_a_uri_root_give_the_same_run(tmp_path):
    local = _run(tmp_path, "local", method="shaped", generations=3)
    uri = f"file://{tmp_path / 'shared'}"
    remote = _run(tmp_path, "remote", method="shaped", generations=3,
                  shaping={**TINY["shaping"], "trajectory_root": uri})
    assert _rewards(remote.read_metrics()) == _rewards(local.read_metrics())
    assert not (remote.root / "trajectories").exists()
    own = tmp_path / "shared" / f"run_{remote.run_id()}"  # each run under its own id in a shared root
    assert sorted(p.name for p in own.iterdir()) == ["gen_000000", "gen_000001", "gen_000002"]


def test_shaped_needs_the_waypoint_contract(tmp_path):
    cfg, store = new_run(tmp_path / "cp", {**TINY, "env": "CartPole-v1", "method": "shaped"})
    with pytest.raises(ConfigError, match="info\\['position'\\]"):
        Trainer(cfg, store, progress=False)


def _close(a, b, rel=1e-4):
    """Rows equal, numbers within a relative float tolerance (the placements batch the same maths
    differently)."""
    assert [r.keys() for r in a] == [r.keys() for r in b]
    for ra, rb in zip(a, b):
        for k in ra:
            if ra[k] == rb[k]:
                continue
            assert float(ra[k]) == pytest.approx(float(rb[k]), rel=rel, abs=1e-6), (ra["generation"], k)


@pytest.mark.parametrize("worker_cache,query_scale,step_change", [(True, "raw", False), (False, "raw", False),
                                                                   (True, "own_step", False), (True, "raw", True)])
def test_master_and_worker_placement_give_the_same_run(tmp_path, monkeypatch, worker_cache, query_scale, step_change):
    from shaped_es.guides import shaped_tasks

    if not worker_cache:  # every clone task reads its members' data from the store
        monkeypatch.setattr(shaped_tasks, "_CACHE_GENERATIONS", 0)
    shaped_tasks._CACHE.clear()
    sh = TINY["shaping"]
    sh = {**sh, "inverse_dynamics": {**sh.get("inverse_dynamics", {}), "query_scale": query_scale,
                                     "step_change": step_change}}  # M_phi's last-step block on both placements
    master = _run(tmp_path, "master", method="shaped", shaping={**sh, "placement": "master"})
    workers = _run(tmp_path, "workers", method="shaped", shaping={**sh, "placement": "workers"})
    a, b = strip_time(master.read_metrics()), strip_time(workers.read_metrics())
    assert float(a[-1]["mphi_iterations"]) > 0 and int(a[-1]["surrogate_rank"]) > 0
    _close(a, b)
    # generation 3 still has the 16 babbling policies (members 12-27) of inverse_dynamics.babble
    assert sorted(p.name for p in (master.root / "trajectories" / "gen_000003").iterdir()) == [
        "members_0000-0027.parquet"]  # the master writes one shard per generation
    assert sorted(p.name for p in (workers.root / "trajectories" / "gen_000003").iterdir()) == [
        "members_0000-0011.parquet", "members_0012-0027.parquet"]  # inline: a task (a shard) each


def test_resume_between_sparse_checkpoints_is_exact(tmp_path, monkeypatch):
    """checkpoint_every=3: a crash at generation 4 re-runs 3 from the checkpoint after 2; the shards
    generation 3 and 4 read must still be there (they were pruned before)."""
    over = dict(method="shaped", generations=6, checkpoint_every=3,
                shaping={**TINY["shaping"], "history": 3})
    full = _run(tmp_path, "full", **over)
    cfg, store = new_run(tmp_path / "crashed", {**TINY, **over})
    run_until_crash(monkeypatch, cfg, store, 4)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full.read_metrics())


@pytest.mark.parametrize("placement", ["master", "workers"])
def test_a_crash_while_shards_are_written_resumes_exactly(tmp_path, monkeypatch, placement):
    """Writing generation 2's shard fails (master: in its background writer; workers: in the task): the
    run stops with the error, no checkpoint names generation 2, and resume rebuilds the same run."""
    from shaped_es.guides import shaped, shaped_tasks

    over = dict(method="shaped", generations=5, shaping={**TINY["shaping"], "placement": placement})
    full = _run(tmp_path, "full", **over)
    cfg, store = new_run(tmp_path / "crashed", {**TINY, **over})
    module = shaped if placement == "master" else shaped_tasks
    write = module.write_shard

    def dying(root, trs, *rest):  # trs: a block of members (data.PackedTransitions) or a list
        if (trs.generation if hasattr(trs, "generation") else trs[0].generation) == 2:
            raise OSError("disk gone")
        return write(root, trs, *rest)

    monkeypatch.setattr(module, "write_shard", dying)
    with pytest.raises(OSError, match="disk gone"):
        Trainer(cfg, store, progress=False).run()
    arrays_meta = store.load_checkpoint()
    assert arrays_meta is not None and arrays_meta[1]["generation"] == 2  # the checkpoint after g=1
    monkeypatch.setattr(module, "write_shard", write)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full.read_metrics())


def test_reference_metrics_and_return_diagnostics_are_logged(tmp_path):
    ref = _run(tmp_path, "ref", method="vanilla")
    sh = {**TINY["shaping"], "reference_run": str(ref.root), "diagnose_returns": True}
    rows = _run(tmp_path, "shaped", method="shaped", shaping=sh).read_metrics()
    last = rows[-1]
    for k in ("mphi_fig5_test_loss", "own_ref_error", "clone_ref_error", "label_beats_own",
              "clone_return_gain", "clone_improved_fraction"):
        assert last[k] != "" and np.isfinite(float(last[k])), k
    assert 0 <= float(last["label_beats_own"]) <= 1 and last["shaping_active"] == "1"
    plain = _run(tmp_path, "plain", method="shaped").read_metrics()
    assert _rewards(plain) == _rewards(rows)  # metrics only: the run itself is unchanged
    # without them, their columns are not written at all (no column stays empty in every row)
    missing = {"mphi_fig5_test_loss", "own_ref_error", "clone_ref_error", "label_beats_own", "clone_return_gain",
               "clone_improved_fraction"}
    assert missing <= set(last) and not missing & set(plain[0])
    assert [k for k in plain[0] if all(r[k] == "" for r in plain)] == []


def test_an_untrained_mphi_is_said_once_and_logged(tmp_path, capsys):
    sh = {**TINY["shaping"], "inverse_dynamics": {"min_return": 1e9, "filter": "total"}}
    rows = _run(tmp_path, "starved", method="shaped", generations=7, shaping=sh).read_metrics()
    assert all(r["shaping_active"] == "0" for r in rows)
    err = capsys.readouterr().err
    assert err.count("no episode passed M_phi's filter") == 1 and "filter=none" in err


def test_gradient_steps_on_process_workers_equal_inline(tmp_path):
    """Master placement on the process executor labels in the master and runs the cloning steps in the
    workers, in chunks: the same run as inline (float tolerance)."""
    inline = _run(tmp_path, "inline", method="shaped").read_metrics()
    proc = _run(tmp_path, "proc", method="shaped", executor="process", workers=2).read_metrics()
    assert float(proc[-1]["mphi_iterations"]) > 0
    _close(strip_time(inline), strip_time(proc))


def test_sigkill_mid_run_and_resume_gives_identical_rows(tmp_path):
    """A real SIGKILL of a shaped run (wherever it lands: rollouts, the background shard write, the
    cloning, a checkpoint), then ``resume``: the same rows as an uninterrupted run."""
    import yaml

    over = {"method": "shaped", "generations": 12}
    cfg = tmp_path / "tiny.yaml"
    cfg.write_text(yaml.safe_dump({**TINY, **over}))

    def cli(*args):
        return popen_cli(*args, "--quiet")

    # the uninterrupted reference is trained in this process (the Trainer the command line runs, one
    # process start-up less); the killed run and its resume are real processes
    full = _run(tmp_path, "full", **over)
    run = tmp_path / "killed"
    p = cli("train", "--config", str(cfg), "--out", str(run))
    done = kill_after_rows(p, run, 5)
    assert 0 < done < 12, "the kill must land mid-run"
    r = cli("resume", str(run))
    assert r.wait(timeout=300) == 0, r.stderr.read()
    assert strip_time(RunStore(run).read_metrics()) == strip_time(full.read_metrics())


def test_a_missing_info_key_is_named():
    """A new user's env returned info['position'] but no info['waypoint']: the line named both keys as needed;
    it now also names the one missing."""
    from shaped_es.config import ConfigError, build_config
    from shaped_es.env_probe import EnvProbe
    from shaped_es.guides.shaped_setup import waypoint_dim

    cfg = build_config({"env": "PointVel-v0", "method": "shaped"})
    probe = EnvProbe(4, 2, 100, reset_info={"position": [0.0, 0.0]})
    with pytest.raises(ConfigError, match=r"its reset info has no 'waypoint' \(see the README"):
        waypoint_dim(cfg, probe)
    assert waypoint_dim(cfg, EnvProbe(4, 2, 100, reset_info={"position": [0.0, 0.0], "waypoint": [1.0, 0.0]})) == 2
    typo = EnvProbe(4, 2, 100, reset_info={"position": [0.0, 0.0], "waypoints": [1.0, 0.0]})
    with pytest.raises(ConfigError, match=r"has no 'waypoint'; did you mean 'waypoints'\? \(see the README"):
        waypoint_dim(cfg, typo)


def test_a_controller_label_run_says_where_its_labels_come_from_once(tmp_path, capsys):
    """A new user's controller-label runs printed nothing about their labels (an M_phi run prints the probe's
    line); a resumed run does not say it again."""
    from helpers import train
    from test_mechanisms import TINY

    sh = {**TINY["shaping"], "labels": "controller"}
    store = train(tmp_path / "run", {**TINY, "generations": 1, "shaping": sh})
    err = capsys.readouterr().err
    assert err.count("labels: the env's waypoint_controller, the oracle") == 1
    assert "(shaping.labels=controller: no label probe, no rival labels)" in err
    Trainer(build_config({**TINY, "generations": 2, "shaping": sh}), store, progress=False).run()  # resumed
    assert len(store.read_metrics()) == 2
    assert "labels: the env's waypoint_controller" not in capsys.readouterr().err
