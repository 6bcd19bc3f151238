"""The mean's clone fitted under parameter noise from ``shaping.mean_clone.noise_from``: metrics.csv's
``clone_noise`` is 0 before it and ``noise * es.sigma`` from it, and the run says so in one line, once."""

import pytest
from helpers import new_run

from shaped_es.trainer import Trainer


def train(root, cfg, progress=True):
    """The run trained with its progress display (the noise line is not said under --quiet)."""
    cfg, store = new_run(root, cfg)
    Trainer(cfg, store, progress=progress).run()
    return store

CFG = {"env": "PointVel-v0", "executor": "inline", "method": "shaped", "generations": 6, "seed": 0,
       "es": {"pairs": 4, "sigma": 0.04}, "policy": {"hidden": [4]},
       "rollout": {"episodes": 1, "test_episodes": 1, "test_every": 3, "max_steps": 20},
       # frame set: no label probe; backoff off: every generation clones
       "shaping": {"inverse_dynamics": {"steps_per_generation": 5, "babble": 0, "frame": "both"}, "history": 2,
                   "backoff_after": 0,
                   "mean_clone": {"steps": 5, "batch_size": 8, "noise": 0.5, "noise_from": 3}},
       "tensorboard": False}


def test_clone_noise_switches_on_at_noise_from_and_the_run_says_so_once(tmp_path, capsys):
    rows = train(tmp_path / "r", CFG).read_metrics()
    err = capsys.readouterr().err
    noise = [float(r["clone_noise"]) if r["clone_noise"] else None for r in rows]
    made = [g for g, x in enumerate(noise) if x is not None]  # generations whose clone was made
    assert made and all(noise[g] == 0.0 for g in made if g < 3) and all(abs(noise[g] - 0.02) < 1e-12 for g in made if g >= 3)
    assert any(g >= 3 for g in made)
    lines = [ln for ln in err.splitlines() if "fitted under the search's parameter noise" in ln]
    assert len(lines) == 1
    first = min(g for g in made if g >= 3)
    assert lines[0].startswith(f"shaped-es: r: generation {first + 1}: the mean's clone is fitted")
    assert "noise_from 3 (counted from 0: the progress line's generation 4" in lines[0]
    assert "shaping.mean_clone.noise 0.5" in lines[0]


def test_a_noise_ramp_grows_the_clones_noise_linearly_and_the_line_says_so(tmp_path, capsys):
    """``noise_ramp`` R: the k-th generation from noise_from (k = 1, 2, ...) clones under min(1, k / R) of the
    noise; the run's one line names the ramp."""
    cfg = {**CFG, "shaping": {**CFG["shaping"], "mean_clone": {**CFG["shaping"]["mean_clone"], "noise_ramp": 2}}}
    rows = train(tmp_path / "r", cfg).read_metrics()
    err = capsys.readouterr().err
    noise = {g: float(r["clone_noise"]) for g, r in enumerate(rows) if r["clone_noise"]}
    want = {3: 0.01, 4: 0.02, 5: 0.02}  # 0.5 * sigma 0.04 = 0.02, half of it at generation 3
    assert {g: noise[g] for g in noise if g >= 3} == pytest.approx({g: want[g] for g in noise if g >= 3})
    assert 3 in noise or 4 in noise
    line = next(ln for ln in err.splitlines() if "fitted under the search's parameter noise" in ln)
    assert "slept), growing to it over noise_ramp 2 generations" in line


def test_noise_scale_is_zero_before_noise_from_then_ramps():
    from shaped_es.guides.mechanisms.mean_clone import noise_scale
    from shaped_es.shaping.settings import MeanCloneConfig

    step = MeanCloneConfig(noise=1.0, noise_from=15)
    assert [noise_scale(step, g) for g in (0, 14, 15, 40)] == [0.0, 0.0, 1.0, 1.0]
    ramp = MeanCloneConfig(noise=0.5, noise_from=15, noise_ramp=4)
    assert [noise_scale(ramp, g) for g in (14, 15, 16, 17, 18, 30)] == [0.0, 0.125, 0.25, 0.375, 0.5, 0.5]
    with pytest.raises(ValueError, match="noise_ramp=-1"):
        MeanCloneConfig(noise_ramp=-1)


def test_over_cmaes_the_clones_noise_follows_cmas_adapted_step(tmp_path):
    """shaped_cmaes: the clone's noise is noise x CMA-ES's search_scale() after each tell (its adapted step), so it
    moves generation by generation instead of staying noise x es.sigma (CMA-ES's initial step)."""
    rows = train(tmp_path / "c", {**CFG, "method": "shaped_cmaes"}).read_metrics()
    noise = [float(r["clone_noise"]) for r in rows[3:] if r["clone_noise"]]
    assert len(noise) >= 2 and all(x > 0 for x in noise)
    assert len(set(noise)) == len(noise) and all(abs(x - 0.02) > 1e-6 for x in noise)


@pytest.mark.parametrize("first", [5, 2])
def test_a_resumed_run_says_the_noise_line_only_if_it_had_not_yet(tmp_path, capsys, first):
    """Extended past noise_from (5 generations, then resumed to 6), the run said the line in its first part and
    does not say it again as if the noise began at the resume (a new user's extension printed it once per seed);
    resumed before noise_from (2, then to 6), it says it once, when the noise begins."""
    from shaped_es.cli.commands import main

    run = tmp_path / "r"
    train(run, {**CFG, "generations": first})
    before = [ln for ln in capsys.readouterr().err.splitlines() if "parameter noise" in ln]
    assert main(["resume", str(run), "--generations", "6"]) == 0
    after = [ln for ln in capsys.readouterr().err.splitlines() if "parameter noise" in ln]
    assert len(before + after) == 1 and len(after) == (first <= 3)


def test_quiet_runs_do_not_say_the_noise_line(tmp_path, capsys):
    """--quiet (a benchmark's runs): the line, the same in every run, is not said; the noise is applied alike."""
    loud = train(tmp_path / "loud", CFG).read_metrics()
    capsys.readouterr()
    quiet = train(tmp_path / "quiet", CFG, progress=False).read_metrics()
    assert "parameter noise" not in capsys.readouterr().err
    assert [r["clone_noise"] for r in quiet] == [r["clone_noise"] for r in loud]
