"""The run loop every method shares: the columns it writes, callbacks that stop a run, ``stop_at`` (a run
that ends early as finished), and the best policy's generation in each checkpoint."""

import json

import pytest

from helpers import CARTPOLE_TINY, new_run, strip_time, train
from shaped_es.guides import NoGuide
from shaped_es.monitor.callbacks import Callback
from shaped_es.config import build_config
from shaped_es.run_loop import BASE_COLUMNS, CALLBACK, STOP_AT, run_finished
from shaped_es.trainer import Trainer

CFG = {**CARTPOLE_TINY, "executor": "inline", "generations": 5}  # test rewards 28.7, 22.7, 33.3, 73, 65


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """The uninterrupted run every early stop is compared with."""
    return train(tmp_path_factory.mktemp("full") / "run", CFG)


def _rows(store):
    return [{k: (float(v) if v != "" else None) for k, v in r.items()} for r in store.read_metrics()]


def test_a_run_writes_only_the_columns_it_fills(full):
    rows = full.read_metrics()
    assert list(rows[0]) == list(BASE_COLUMNS)
    assert not [k for k in rows[0] if all(r[k] == "" for r in rows)]


def test_an_undeclared_column_with_a_value_is_a_bug(tmp_path):
    cfg, store = new_run(tmp_path / "r", CFG)
    loop = Trainer(cfg, store, progress=False)
    try:
        assert loop.metrics_row({"generation": 0, "extra": None}) == {k: (0 if k == "generation" else None)
                                                                     for k in BASE_COLUMNS}
        with pytest.raises(RuntimeError, match="not declared"):
            loop.metrics_row({"generation": 0, "extra": 1.0})
    finally:
        loop.close()


def test_a_callback_sees_every_row_and_stops_the_run_resumably(tmp_path, full):
    seen = []

    def stop_after_three(row):
        seen.append(row)
        return row["generation"] < 2  # False on the third row: stop

    cfg, store = new_run(tmp_path / "r", CFG)
    rows = Trainer(cfg, store, progress=False, callback=stop_after_three).run()
    assert [r["generation"] for r in seen] == [0, 1, 2, 3]  # the row still waiting was completed too
    assert rows == seen and list(rows[0]) == list(BASE_COLUMNS)
    meta = store.checkpoint_meta()
    assert meta["generation"] == 4 and meta["stopped"] == CALLBACK and not run_finished(cfg, store)
    Trainer(cfg, store, progress=False).run()  # a callback's stop is not an end: resume continues exactly
    assert strip_time(store.read_metrics()) == strip_time(full.read_metrics())


def test_a_callback_object_and_a_list_of_them(tmp_path):
    class Count(Callback):
        def on_start(self, run):
            super().on_start(run)
            self.rows, self.ended = 0, None

        def on_generation(self, row):
            self.rows += 1
            assert self.run.c.generation >= row["generation"]

        def on_end(self, rows):
            self.ended = len(rows)

    counts = [Count(), Count()]
    cfg, store = new_run(tmp_path / "r", CFG)
    Trainer(cfg, store, progress=False, callback=counts).run()
    assert [(c.rows, c.ended) for c in counts] == [(5, 5), (5, 5)]
    with pytest.raises(TypeError, match="callback"):
        Trainer(cfg, store, progress=False, callback=3)


def test_stop_at_ends_the_run_as_finished(tmp_path, full):
    rows = _rows(full)
    hit = next(r for r in rows if r["test_reward_mean"] >= 30)  # the first test reward reaching 30
    assert 0 < hit["generation"] < len(rows) - 2  # ... early enough to stop the run early
    cfg, store = new_run(tmp_path / "r", {**CFG, "stop_at": 30})
    Trainer(cfg, store, progress=False).run()
    stopped = store.read_metrics()
    assert len(stopped) == hit["generation"] + 2  # that row, and the next generation's (already run)
    assert strip_time(stopped) == strip_time(full.read_metrics())[: len(stopped)]
    assert store.checkpoint_meta()["stopped"] == STOP_AT and run_finished(cfg, store)
    assert Trainer(cfg, store, progress=False).run() == []  # resume: finished, nothing to do
    assert len(store.read_metrics()) == len(stopped)
    # without stop_at (edited out of its config.yaml) the run continues, exactly
    cfg = build_config({**CFG, "stop_at": None})
    assert not run_finished(cfg, store)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == strip_time(full.read_metrics())


def test_the_checkpoint_names_the_best_policys_generation(full):
    rows = _rows(full)
    best = max(range(len(rows)), key=lambda i: (rows[i]["test_reward_mean"], -i))  # first of the best
    meta = json.loads(sorted((full.root / "checkpoints").glob("gen_*.json"))[-1].read_text())
    assert meta["best_generation"] == best + 1 < meta["generation"] and meta["stopped"] is None


def test_the_elapsed_time_counts_the_start_up_and_a_resumed_runs_wall_time(tmp_path, monkeypatch):
    """The progress line's elapsed time starts with the run: the start-up before generation 0 (worker
    pools, the env probe, the shaped method's label probe; here an env probe made 1 s slower) is in it, and
    a resumed run's continues from the wall time its checkpoint saved (generations made 0.5 s slower)."""
    import time

    from shaped_es import run_loop, trainer

    seen = []

    class Recording(run_loop.ProgressDisplay):
        def __init__(self, *args, **kwargs):
            seen.append(kwargs["elapsed"])
            super().__init__(*args, **kwargs)

    probe = trainer.probe_env

    def slow_probe(*args, **kwargs):
        time.sleep(1.0)
        return probe(*args, **kwargs)

    def slow_generation(self, g):  # inside the generation's clock
        time.sleep(0.5)

    monkeypatch.setattr(run_loop, "ProgressDisplay", Recording)
    monkeypatch.setattr(trainer, "probe_env", slow_probe)
    monkeypatch.setattr(NoGuide, "begin_generation", slow_generation)
    cfg, store = new_run(tmp_path / "r", {**CFG, "generations": 2})
    Trainer(cfg, store, progress=False).run()
    assert 1.0 <= seen[0] < 10.0
    saved = store.checkpoint_meta()["wall_time_s"]
    assert saved >= 1.0  # two generations of 0.5 s
    Trainer(build_config({**CFG, "generations": 3}), store, progress=False).run()  # resumed
    assert saved + 1.0 <= seen[1] < saved + 10.0


@pytest.mark.slow  # 11-19 s of real processes: the full suite runs it (CI's fast suite stays under 10 min)
def test_ppo_shares_callbacks_and_stop_at(tmp_path):
    from shaped_es.baselines.ppo import train_ppo

    cfg, store = new_run(tmp_path / "p", {**CFG, "method": "ppo", "generations": 3,
                                          "ppo": {"n_steps": 64, "batch_size": 32, "n_epochs": 1}})
    rows = train_ppo(cfg, store, progress=False, callback=lambda row: False)
    assert len(rows) == 1 and store.checkpoint_meta()["stopped"] == CALLBACK
    cfg = build_config({**cfg.model_dump(), "stop_at": -1e9})  # any test reward reaches it
    assert len(train_ppo(cfg, store, progress=False)) == 1 and run_finished(cfg, store)
    assert len(store.read_metrics()) == 2 and store.checkpoint_meta()["best_generation"] in (1, 2)
