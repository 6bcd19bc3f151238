"""The mean's clone fitted under parameter noise from ``shaping.mean_clone.noise_from``: metrics.csv's
``clone_noise`` is 0 before it and ``noise * es.sigma`` from it, and the run says so in one line, once."""

from helpers import train

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
    assert "noise_from 3" in lines[0] and "shaping.mean_clone.noise 0.5" in lines[0]
