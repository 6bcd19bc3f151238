"""The label probe's best simulated candidate, judged beside generation 0 (guides/probe_candidate.py): a win
makes it the mean, a loss leaves the run training exactly as without it and is not counted by the label
budget; kept beside label_probe.json (a restart in generation 0 judges the same one), checked when read; a run
saved before the setting reads it as off."""

import numpy as np
import pytest

from shaped_es.config import ConfigError, build_config
from shaped_es.guides import probe_candidate, probe_file
from shaped_es.rundir.store import RunStore
from tests.helpers import train

POINT = {"env": "PointVel-v0", "method": "shaped", "generations": 4, "seed": 2, "executor": "inline",
         "es": {"pairs": 4}, "rollout": {"episodes": 1, "test_episodes": 1}, "tensorboard": False}
OFF = {**POINT, "shaping": {"mean_clone": {"probe_candidate": False}}}


def test_best_takes_the_highest_mean_return():
    thetas = {"a": np.zeros(3), "b": np.ones(3), "shoot:4": np.full(3, 2.0)}
    name, theta = probe_candidate.best({"a": [1.0, 2.0], "b": [0.0, 5.0], "shoot:4": [2.5, 2.5]}, thetas)
    assert name == "b" and theta.dtype == np.float32 and (theta == 1).all()
    assert probe_candidate.best({"a": [1.0]}, {}) is None


def test_a_winning_probe_candidate_becomes_the_mean_at_generation_0(tmp_path, capsys):
    rows = train(tmp_path / "on", POINT).read_metrics()
    err = capsys.readouterr().err
    off = train(tmp_path / "off", OFF).read_metrics()
    assert rows[0]["candidate_accepted"] == "1" and off[0]["candidate_accepted"] == ""
    assert rows[0]["candidate_rival"] == "5"  # mechanisms/candidate.PROBE: no label source's row (the report's count)
    assert all(r["candidate_rival"] in ("0", "1", "2", "3", "4", "") for r in rows[1:])
    assert "generation 1: the label probe's best simulated candidate (" in err and "won: it is the search's mean" in err
    assert float(rows[1]["test_reward_mean"]) > float(off[1]["test_reward_mean"]) + 3  # PointVel's labels drive
    from shaped_es.rollout import policy_spec

    saved = probe_candidate.load(tmp_path / "on" / probe_candidate.FILE, policy_spec(build_config(POINT)).num_params)
    assert saved is not None and np.isfinite(saved).all()  # beside label_probe.json, this policy's size


def test_a_losing_probe_candidate_changes_nothing_but_its_episodes(tmp_path, monkeypatch, capsys):
    real = probe_candidate.best

    def bad(returns, thetas):  # the best clone, made hopeless: far out, saturated
        name, theta = real(returns, thetas)
        return name, theta + 50.0

    monkeypatch.setattr(probe_candidate, "best", bad)
    rows = train(tmp_path / "on", POINT).read_metrics()
    err = capsys.readouterr().err  # which test it failed is label_check.candidate_line's (test_label_probe.py)
    assert "not counted by the back-off (it shows in labels A/J), the run goes on as without it" in err and "won: it is" not in err
    off = train(tmp_path / "off", OFF).read_metrics()
    assert rows[0]["candidate_accepted"] == "0"
    for key in ("train_reward_mean", "test_reward_mean", "mphi_dataset_size", "candidate_accepted"):
        assert [r[key] for r in rows[1:]] == [r[key] for r in off[1:]], key
    assert [r["train_reward_mean"] for r in rows[:1]] == [r["train_reward_mean"] for r in off[:1]]
    assert int(rows[0]["env_steps"]) > int(off[0]["env_steps"])  # its and the mean's episodes


def test_a_bad_candidate_file_is_one_line(tmp_path):
    path = tmp_path / probe_candidate.FILE
    assert probe_candidate.load(path, 5) is None  # none on file: none judged
    probe_candidate.save(path, np.arange(4.0))
    with pytest.raises(ConfigError, match=r"holds \(4,\) parameters, expected \(5,\)"):
        probe_candidate.load(path, 5)
    for damaged in (b"not numpy", b""):  # an empty file (a crash's) too: numpy raises EOFError there
        path.write_bytes(damaged)
        with pytest.raises(ConfigError) as err:
            probe_candidate.load(path, 4)
        assert "\n" not in str(err.value) and "is not a probe candidate" in str(err.value)


def test_a_run_saved_before_the_setting_reads_it_as_off(tmp_path):
    store = RunStore(tmp_path / "old")
    store.create(build_config(POINT))
    text = store.config_path.read_text()
    assert "probe_candidate: true" in text
    store.config_path.write_text(text.replace("    probe_candidate: true\n", ""))
    assert store.read_config().shaping.mean_clone.probe_candidate is False
    assert probe_file.FILE == "label_probe.json"  # the candidate's file sits beside it


class _Host:  # a stub shaped guide: the probe's candidate, no labels trained yet (generation 0)
    def __init__(self, n, candidate):
        from shaped_es.shaping.settings import MeanCloneConfig

        self.mean_clone_cfg = MeanCloneConfig(accept="mean", extra_episodes=0)
        self.labels = type("L", (), {"ready": False})()
        self.rivals = []
        self.probe_candidate = candidate
        self.spec = type("S", (), {"num_params": n, "init": staticmethod(lambda seed: np.zeros(n, np.float32))})()
        self.cfg = type("C", (), {"seed": 0, "rollout": type("R", (), {"episodes": 1})()})()


@pytest.mark.parametrize("candidate_return, accepted", [(5.0, False), (20.0, True)])
def test_the_probe_candidate_must_also_beat_every_member(candidate_return, accepted):
    """On the swimmer the probe's clone beat the initial mean but not the members the search sampled around
    it (17-26 against 5 at most), and the runs it jumped to were slower."""
    from shaped_es.guides.mechanisms.candidate import MeanCandidate
    from shaped_es.strategies import GuidedES

    n = 3
    mech = MeanCandidate(_Host(n, np.full(n, 7.0, np.float32)))
    assert mech.probe_rows and mech.extra_members(0).shape == (2, n)  # the candidate, the initial mean
    es = GuidedES(np.zeros(n), sigma=0.1, pairs=2, seed=0)
    es.ask()
    old = np.array(es.mean)
    fitness = np.array([1.0, 10.0, 2.0, 3.0])  # (P,) one member at 10
    es.tell(fitness)
    out = mech.after_tell(0, None, fitness, np.array([[candidate_return], [0.0]]), [], old, es, None)
    assert out["candidate_accepted"] == int(accepted) and mech.free_judgement and not mech.probe_rows
    assert np.allclose(es.mean[0], 7.0, atol=1.0) == accepted  # the jump (plus the ES step it keeps)
