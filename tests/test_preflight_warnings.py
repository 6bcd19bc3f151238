"""Settings a method never reads (``shaping.*`` with vanilla, ``ppo.*`` with an ES method, ``es.alpha``
with vanilla) are one warning line before the run starts (``preflight.warn_ignored``); the method's own
settings, and a benchmark's shared ones, are not."""

import warnings

import pytest

from shaped_es.cli.commands import main
from shaped_es.config import ConfigWarning, build_config
from shaped_es.preflight import check_run, warn_ignored


@pytest.mark.parametrize("method", ["vanilla", "cmaes", "ppo"])
def test_shaping_settings_with_another_method_warn_once(method):
    cfg = build_config({"method": method, "shaping": {"labels": "controller", "cloning": {"steps": 5}}})
    with pytest.warns(ConfigWarning) as rec:
        warn_ignored(cfg)
    assert len(rec) == 1
    text = str(rec[0].message)
    assert text.startswith(f"--method {method} ignores shaping.labels, shaping.cloning.steps")
    assert "only --method shaped / shaped_cmaes use them" in text


def test_other_sections_name_who_reads_them():
    cfg = build_config({"method": "vanilla", "es": {"alpha": 0.5}, "ppo": {"n_steps": 64}})
    with pytest.warns(ConfigWarning, match=r"es.alpha \(only --method guided / shaped use it\); ppo.n_steps "
                                           r"\(only --method ppo uses it\)"):
        warn_ignored(cfg)


@pytest.mark.parametrize("data", [
    {"method": "vanilla", "es": {"sigma": 0.1}, "rollout": {"episodes": 1}},  # its own settings
    {"method": "shaped", "shaping": {"labels": "controller"}, "es": {"alpha": 0.5}},
    {"method": "ppo", "es": {"pairs": 8}, "ppo": {"n_steps": 64}},  # es.pairs: PPO's env-step budget
    {"method": "vanilla"},
])
def test_settings_the_method_reads_do_not_warn(data):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_ignored(build_config(data))


def test_check_run_warns_unless_told_not_to():
    cfg = build_config({"env": "CartPole-v1", "method": "vanilla", "shaping": {"eta": 0.1}})
    with pytest.warns(ConfigWarning, match="shaping.eta"):
        check_run(cfg)
    with warnings.catch_warnings():  # a benchmark: its settings are shared by its methods on purpose
        warnings.simplefilter("error", ConfigWarning)
        check_run(cfg, warn=False)


def test_train_prints_one_warning_line(tmp_path, capsys):
    argv = ["train", "--env", "CartPole-v1", "--method", "vanilla", "--generations", "1", "--pairs", "2",
            "--executor", "inline", "--set", "rollout.episodes=1", "--set", "rollout.test_episodes=1",
            "--set", "tensorboard=false", "--set", "shaping.labels=reference", "--quiet",
            "--out", str(tmp_path / "run")]
    assert main(argv) == 0
    err = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert err == ["shaped-es: warning: --method vanilla ignores shaping.labels (only --method shaped / shaped_cmaes use it)"]


@pytest.mark.parametrize("over,says", [({"shoot_hold": True}, "shoot_hold is on"),
                                       ({"rival_shoot": False}, "rival_shoot is off"), ({}, None)])
def test_a_setting_another_one_turns_off_warns(over, says):
    """A new user's rival_hold was dropped without a word where shoot_hold was on."""
    cfg = build_config({"method": "shaped", "shaping": {"inverse_dynamics": {"rival_hold": True, **over}}})
    if says is None:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            warn_ignored(cfg)
        return
    with pytest.warns(ConfigWarning, match=f"rival_hold is ignored: {says}"):
        warn_ignored(cfg)
