"""Videos during training (``--set video_every=N``): every N generations the best policy so far as
``RUN/videos/gen_NNNNNN.gif``; off by default; no result changes; an env that cannot render is one line
before the first generation."""

import json

from helpers import strip_time
from shaped_es.cli.commands import main
from shaped_es.rundir.store import RunStore

ARGS = ["--env", "CarNav-v0", "--method", "vanilla", "--executor", "inline", "--generations", "4", "--pairs", "2",
        "--set", "rollout.episodes=1", "--set", "rollout.test_episodes=1", "--set", "rollout.max_steps=15",
        "--set", "policy.hidden=[4]", "--set", "tensorboard=false", "--set", "checkpoint_every=4"]


def test_video_every_writes_gifs_and_changes_no_result(tmp_path, capsys):
    from PIL import Image

    plain, video = tmp_path / "plain", tmp_path / "video"
    assert main(["train", *ARGS, "--quiet", "--out", str(plain)]) == 0
    assert not (plain / "videos").exists()  # off by default
    assert main(["train", *ARGS, "--set", "video_every=2", "--out", str(video)]) == 0
    assert sorted(p.name for p in (video / "videos").iterdir()) == ["gen_000002.gif", "gen_000004.gif"]
    with Image.open(video / "videos" / "gen_000002.gif") as gif:
        assert 2 <= gif.n_frames <= 16  # reset + up to 15 steps (rollout.max_steps)
    assert strip_time(RunStore(video).read_metrics()) == strip_time(RunStore(plain).read_metrics())
    err = capsys.readouterr().err
    assert f"video of the best policy (return " in err and str(video / "videos" / "gen_000004.gif") in err


def test_video_every_on_an_env_that_cannot_render_is_one_line(tmp_path, capsys, monkeypatch):
    from shaped_es.trained import render

    def no_frames(env_id, env_kwargs):
        raise render.EnvSpecError(f"env {env_id!r} cannot render rgb_array frames (render modes: [])")

    monkeypatch.setattr(render, "_rgb_env", no_frames)
    assert main(["train", *ARGS, "--quiet", "--set", "video_every=1", "--out", str(tmp_path / "r")]) == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "shaped-es: error: env 'CarNav-v0' cannot render rgb_array frames (render modes: [])"]
    assert not (tmp_path / "r").exists()  # refused before the run wrote anything: the same --out can be retried


def test_video_every_must_be_positive(tmp_path, capsys):
    assert main(["train", *ARGS, "--set", "video_every=0", "--out", str(tmp_path / "r")]) == 2
    assert "video_every: Input should be greater than 0" in capsys.readouterr().err
