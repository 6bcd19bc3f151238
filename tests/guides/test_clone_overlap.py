"""``clone_overlap`` (issue #28): the next generation's population rolls out while the master clones the
mean, its candidate's rollouts follow the clone. The numbers are the sequential loop's: the same metrics
rows (times aside) and the same checkpoint arrays, inline and on 2 worker processes; the overlap really
ran; a run resumed from the middle of an overlapped run continues exactly."""

import numpy as np
import pytest

from helpers import new_run, run_until_crash, strip_time
from shaped_es.trainer import Trainer

CAR = {
    "env": "CarNav-v0",
    "method": "shaped",
    "generations": 5,
    "seed": 3,
    "es": {"pairs": 8},
    "policy": {"hidden": [16]},
    "rollout": {"episodes": 2, "test_episodes": 2, "max_steps": 100},
    "shaping": {"inverse_dynamics": {"steps_per_generation": 50, "filter": "none", "babble": 4},
                "mean_clone": {"steps": 20, "batch_size": 64, "record_every": 4}, "history": 2},
    "tensorboard": False,
    "clone_overlap": True,  # opt-in
}
VARIANTS = {
    "mphi": {},  # M_phi's labels, babblers among the extras
    # the controller's labels; one lost judgement puts the guide to sleep: the verdict is taken before
    # the clone, and the next population's record mask (none while asleep) goes with it
    "backoff": {"shaping": {**CAR["shaping"], "labels": "controller", "backoff_after": 1, "backoff_max": 2}},
    "obs_norm": {"es": {**CAR["es"], "obs_norm": True}},
}


def _run(root, cfg: dict, executor: str) -> tuple[list[dict], dict, int]:
    cfg, store = new_run(root, {**cfg, "executor": executor, "workers": 2})
    trainer = Trainer(cfg, store, progress=False)
    trainer.run()
    arrays, _ = store.load_checkpoint()
    arrays = {k: np.asarray(v) for k, v in arrays.items() if k != "checkpoint/run_id"}
    return strip_time(store.read_metrics()), arrays, trainer.overlapped


@pytest.mark.parametrize("executor", ["inline", "process"])
@pytest.mark.parametrize("variant", list(VARIANTS))
def test_overlapped_clone_gives_the_sequential_run(tmp_path, executor, variant):
    cfg = {**CAR, **VARIANTS[variant]}
    rows, arrays, overlapped = _run(tmp_path / "on", cfg, executor)
    seq_rows, seq_arrays, seq_overlapped = _run(tmp_path / "off", {**cfg, "clone_overlap": False}, executor)
    assert seq_overlapped == 0 and overlapped >= 2  # generations whose population started during a clone
    assert any(r["candidate_return"] != "" for r in rows)
    assert rows == seq_rows
    assert arrays.keys() == seq_arrays.keys()
    for k in arrays:
        np.testing.assert_array_equal(arrays[k], seq_arrays[k], err_msg=k)


def test_an_overlapped_run_resumes_exactly(tmp_path, monkeypatch):
    """A crash in generation 3 (the checkpoint after generation 2 was written while generation 3's
    population rolled out), then a new trainer: the rows of the uninterrupted run."""
    full, _, _ = _run(tmp_path / "full", CAR, "inline")
    cfg, store = new_run(tmp_path / "crashed", {**CAR, "executor": "inline"})
    run_until_crash(monkeypatch, cfg, store, 3)
    Trainer(cfg, store, progress=False).run()
    assert strip_time(store.read_metrics()) == full


def test_cmaes_keeps_the_sequential_path(tmp_path):
    """CMA-ES's ask draws from its RNG state (in the checkpoint): its next population is not asked early."""
    cfg = {**CAR, "method": "shaped_cmaes", "generations": 3}
    _, _, overlapped = _run(tmp_path / "cma", cfg, "inline")
    assert overlapped == 0
