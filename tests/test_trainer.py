"""Tiny end-to-end runs on CartPole-v1: learning, executor independence, kill-and-resume."""

import numpy as np
import pytest

from helpers import CARTPOLE_TINY, kill_after_rows, new_run, popen_cli, run_until_crash, strip_time, train
from shaped_es.rundir.store import RunStore
from shaped_es.trainer import Trainer

TINY = CARTPOLE_TINY


def _train(tmp_path, name, **over):
    return train(tmp_path / name, {**TINY, **over}).read_metrics()


@pytest.mark.parametrize("method", ["vanilla", "guided", "cmaes"])
def test_tiny_train_improves(tmp_path, method):
    rows = _train(tmp_path, method, method=method, executor="inline", generations=8)
    assert len(rows) == 8
    first = float(rows[0]["train_reward_mean"])
    best_late = max(float(r["train_reward_mean"]) for r in rows[-3:])
    assert best_late > 1.5 * first, (first, best_late)
    assert (tmp_path / method / "checkpoints" / "latest.json").is_file()


def test_inline_equals_process(tmp_path):
    a = _train(tmp_path, "inline", executor="inline", method="guided")
    b = _train(tmp_path, "proc", executor="process", workers=2, method="guided")
    assert strip_time(a) == strip_time(b)


def test_overlapped_and_separate_evaluation_equal_blocking(tmp_path):
    blocking = _train(tmp_path, "blocking", executor="process", workers=2, eval_overlap=False)
    overlap = _train(tmp_path, "overlap", executor="process", workers=2)
    separate = _train(tmp_path, "separate", executor="process", workers=1, eval_workers=1)
    assert strip_time(overlap) == strip_time(blocking) == strip_time(separate)
    assert all(r["test_reward_mean"] != "" for r in overlap)


def _crash_and_resume(tmp_path, monkeypatch, crash_at: int, **over):
    """Run until ``step(crash_at)`` raises; returns (full run's rows, rows the crash left, rows after resume)."""
    full = _train(tmp_path, "full", **over)
    cfg, store = new_run(tmp_path / "crashed", {**TINY, **over})
    run_until_crash(monkeypatch, cfg, store, crash_at)
    left = [int(r["generation"]) for r in store.read_metrics()]
    Trainer(cfg, store, progress=False).run()
    return full, left, store.read_metrics()


def test_resume_resubmits_test_episodes_in_flight_at_the_checkpoint(tmp_path, monkeypatch):
    # the checkpoint after g=3 holds row 3, its test episodes still in flight; step 4 dies before them
    full, left, resumed = _crash_and_resume(tmp_path, monkeypatch, 4, executor="inline", generations=8,
                                            checkpoint_every=2)
    assert left == [0, 1, 2], left  # row 3 waited for its test episodes when the run died
    assert strip_time(resumed) == strip_time(full)


def test_resume_drops_rows_written_after_the_checkpoint(tmp_path, monkeypatch):
    # the checkpoint after g=2 held row 2 in flight; steps 3 and 4 wrote rows 2 and 3, then step 5 dies
    full, left, resumed = _crash_and_resume(tmp_path, monkeypatch, 5, executor="inline", generations=8,
                                            checkpoint_every=3)
    assert left == [0, 1, 2, 3]
    assert strip_time(resumed) == strip_time(full)


def test_kill_and_resume_gives_identical_rows(tmp_path):
    cfg = tmp_path / "tiny.yaml"
    import yaml

    over = {"generations": 14, "executor": "inline"}
    cfg.write_text(yaml.safe_dump({**TINY, **over}))
    # the uninterrupted reference is trained in this process (the Trainer the command line runs, one
    # process start-up less); the killed run and its resume are real processes
    train(tmp_path / "full", {**TINY, **over})

    run = tmp_path / "killed"
    p = popen_cli("train", "--config", str(cfg), "--out", str(run), "--quiet")
    n_before = kill_after_rows(p, run, 4, poll=0.02)
    assert 0 < n_before < 14, "the kill must land mid-run"
    r = popen_cli("resume", str(run), "--quiet")
    assert r.wait(timeout=300) == 0, r.stderr.read()
    a = RunStore(tmp_path / "full").read_metrics()
    b = RunStore(run).read_metrics()
    assert len(b) == 14
    assert strip_time(a) == strip_time(b)


@pytest.mark.parametrize(
    "args, needle",
    [
        (["train", "--env", "NoSuchEnv-v0", "--out", "{tmp}/a"], "NoSuchEnv-v0"),
        (["train", "--env", "nomod_xyz:Foo-v0", "--out", "{tmp}/b"], "nomod_xyz"),
        (["train", "--config", "{tmp}/missing.yaml", "--out", "{tmp}/c"], "not found"),
        (["train", "--env", "CartPole-v1", "--set", "es.sigma=-2", "--out", "{tmp}/d"], "es.sigma"),
        (["train", "--env", "CartPole-v1", "--set", "nonsense", "--out", "{tmp}/e"], "KEY=VALUE"),
        (["train", "--env", "CartPole-v1", "--set", "es.colour=3", "--out", "{tmp}/f"], "es.colour"),
        (["resume", "{tmp}/nothing-here"], "nothing-here is not a run directory: it does not exist"),
        (["train", "--env", "CartPole-v1", "--set", "es.sigma", "0.1", "--out", "{tmp}/g"], "expects KEY=VALUE"),
        (["evaluate", "{tmp}/nothing-here"], "not a run directory"),
    ],
)
def test_cli_bad_input_one_line_exit_2(tmp_path, args, needle):
    p = popen_cli(*[a.format(tmp=tmp_path) for a in args])
    out, err = p.communicate(timeout=120)
    assert p.returncode == 2, err
    lines = [l for l in err.splitlines() if l.strip()]
    assert len(lines) == 1 and needle in lines[0] and lines[0].startswith("shaped-es: error:"), err
    assert not (tmp_path / "a" / "config.yaml").exists()


def test_cli_existing_run_refused_and_untouched(tmp_path):
    # the existing run is trained in this process; the refused command is a process of its own
    train(tmp_path / "r", {"env": "CartPole-v1", "generations": 1, "executor": "inline", "es": {"pairs": 2},
                           "rollout": {"test_episodes": 1}})
    before = (tmp_path / "r" / "metrics.csv").read_bytes()
    q = popen_cli("train", "--env", "CartPole-v1", "--out", str(tmp_path / "r"))
    _, err = q.communicate(timeout=60)
    assert q.returncode == 2 and "already holds a run" in err
    assert (tmp_path / "r" / "metrics.csv").read_bytes() == before


@pytest.mark.parametrize("method", ["vanilla", "cmaes"])
def test_test_policy_mean_tests_the_updated_mean(tmp_path, monkeypatch, method):
    # rollout.test_policy=mean: each generation's test episodes go to the search's mean, the centre of the
    # population that generation sampled (not its best member)
    tested, means = [], []
    submit, step = Trainer._submit_eval, Trainer.step

    def spy_submit(self, item, theta, g, obs_norm):
        tested.append(np.array(theta))
        return submit(self, item, theta, g, obs_norm)

    def spy_step(self, g):
        means.append(np.asarray(self.strategy.mean, np.float32).copy())
        return step(self, g)

    monkeypatch.setattr(Trainer, "_submit_eval", spy_submit)
    monkeypatch.setattr(Trainer, "step", spy_step)
    rows = _train(tmp_path, "mean", method=method, executor="inline", generations=4,
                  rollout={**TINY["rollout"], "test_policy": "mean"})
    assert len(tested) == len(means) == 4 and all(r["test_reward_mean"] != "" for r in rows)
    for t, m in zip(tested, means):
        np.testing.assert_array_equal(t, m)
    assert not np.array_equal(tested[-1], tested[0])  # the mean moved


def test_test_policy_mean_resumes_exactly(tmp_path, monkeypatch):
    over = dict(executor="inline", generations=8, checkpoint_every=2,
                rollout={**TINY["rollout"], "test_policy": "mean"})
    full, left, resumed = _crash_and_resume(tmp_path, monkeypatch, 4, **over)
    assert left == [0, 1, 2]
    assert strip_time(resumed) == strip_time(full)
    best = _train(tmp_path, "best", **{**over, "rollout": {**TINY["rollout"], "test_policy": "best"}})
    assert [r["test_reward_mean"] for r in best] != [r["test_reward_mean"] for r in full]  # another policy


def test_an_interrupt_during_start_up_ends_the_executors_it_made(tmp_path, monkeypatch):
    """A Ctrl-C while the trainer is still being built (the shaped method's label probe runs there, on the
    executor's workers) shuts the executors the trainer made: a worker still starting would otherwise die on
    its pool's semaphores, gone with the trainer, and print a traceback after the one-line message."""
    import shaped_es.trainer as trainer_mod

    made = []

    class Recorder:
        workers = 1

        def __init__(self, *a, **k):
            self.closed = 0
            made.append(self)

        def shutdown(self):
            self.closed += 1

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(trainer_mod, "make_executor", Recorder)
    monkeypatch.setattr(trainer_mod, "build_guide", interrupted)
    cfg, store = new_run(tmp_path / "r", {**TINY, "executor": "process", "eval_workers": 1})
    with pytest.raises(KeyboardInterrupt):
        Trainer(cfg, store, progress=False)
    assert [e.closed for e in made] == [1, 1]  # training's and evaluation's pools, each once
    given = Recorder()
    with pytest.raises(KeyboardInterrupt):
        Trainer(cfg, store, executor=given, progress=False)
    assert given.closed == 0  # a caller's executor stays the caller's to close
