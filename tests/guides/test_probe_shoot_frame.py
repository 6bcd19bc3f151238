"""The label probe's choice of the shooting labels' frame (guides/probe_shoot_frame.py): by the held-out error of
each frame's model on the probe's data generations, the waypoint frame only at half the world frame's error or
less; the configured frame where one is set; the world frame where the choice cannot be made."""

from types import SimpleNamespace

import numpy as np
import pytest

from helpers import egocentric_car
from shaped_es.data import Transitions
from shaped_es.guides import clone_probe, probe_shoot_frame
from shaped_es.shaping.forward_shoot import ForwardChunk
from shaped_es.shaping.settings import InverseDynamicsConfig

CFG = InverseDynamicsConfig(hidden=(32, 32), lr=3e-3, steps_per_generation=1500, seed=0)


def world_car(n_eps=60, T=30, seed=0) -> Transitions:
    """The same car, seeing its world heading and the waypoint's world offset: the world frame's body."""
    tr = egocentric_car(n_eps, T, seed)
    v = np.zeros_like(tr.position)  # (T, 2) the last step, a heading proxy
    same = tr.episode[1:] == tr.episode[:-1]
    v[1:][same] = tr.position[1:][same] - tr.position[:-1][same]
    state = np.concatenate([tr.waypoint - tr.position, 20 * v], axis=1).astype(np.float32)  # (T, 4)
    return Transitions(0, 0, tr.episode, tr.step, state, tr.position, tr.waypoint, tr.action, tr.reward)


def _data(body):
    return [[body(seed=0)], [body(seed=1)]]  # two probe generations, one member each


def test_an_egocentric_car_gets_the_waypoint_frame_and_a_world_one_the_world_frame():
    frame, errors = probe_shoot_frame.choose(2, 2, 2, _data(egocentric_car), CFG, 4)
    assert frame == "waypoint" and errors["waypoint"] <= probe_shoot_frame.RATIO * errors["world"], errors
    frame, errors = probe_shoot_frame.choose(4, 2, 2, _data(world_car), CFG, 4)
    assert frame == "world" and errors["world"] < errors["waypoint"], errors


def test_no_choice_without_two_coordinates_or_two_data_generations():
    assert probe_shoot_frame.choose(2, 1, 2, _data(egocentric_car), CFG, 4) == ("world", {})
    assert probe_shoot_frame.choose(2, 2, 2, _data(egocentric_car)[:1], CFG, 4) == ("world", {})


@pytest.mark.parametrize("configured, model, want", [("world", "chunk", "world"), ("waypoint", "chunk", "waypoint"),
                                                     ("auto", "rollout", "world")])
def test_a_configured_frame_or_the_rollout_model_decides_without_fitting(monkeypatch, configured, model, want):
    monkeypatch.setattr(probe_shoot_frame, "choose", lambda *a: pytest.fail("fitted"))
    mp = SimpleNamespace(shoot_frame=configured, shoot_model=model, shoot_horizon=4)
    spec = SimpleNamespace(obs_dim=2, act_dim=2)
    assert probe_shoot_frame.decide(mp, spec, 2, _data(egocentric_car), CFG) == (want, {})


def test_a_configured_waypoint_frame_on_a_1d_waypoint_space_is_refused_before_the_run():
    from shaped_es.config import ConfigError, build_config
    from shaped_es.guides.shaped_setup import check_shoot_frame

    cfg = build_config({"env": "PointVel-v0", "method": "shaped",
                        "shaping": {"inverse_dynamics": {"shoot_frame": "waypoint"}}})
    with pytest.raises(ConfigError, match="needs a waypoint space of at least two coordinates"):
        check_shoot_frame(cfg, 1)
    check_shoot_frame(cfg, 2)


@pytest.mark.parametrize("world, waypoint, want", [(1.3, 0.5, "waypoint"), (1.0, 0.8, "waypoint"),
                                                   (1.3, 1.1, "world"),  # the waypoint frame no clearly better
                                                   (0.6, 0.1, "world")])  # the world frame's model explains some
def test_the_waypoint_frame_only_where_the_world_frames_model_explains_nothing(monkeypatch, world, waypoint, want):
    monkeypatch.setattr(clone_probe, "fit_on", lambda model, data: model)  # cross_fitted fits with it
    monkeypatch.setattr(ForwardChunk, "unexplained", lambda m, trs: world if m.frame == "world" else waypoint)
    frame, errors = probe_shoot_frame.choose(2, 2, 2, _data(egocentric_car), CFG, 4)
    assert (frame, errors) == (want, {"world": world, "waypoint": waypoint})


def test_check_env_says_the_waypoint_frame_and_why():
    from shaped_es.guides.label_check import frame_text
    from shaped_es.guides.probe_result import ProbeResult

    res = ProbeResult("both", None, {}, 0, 0.0, "r", shoot_frame="waypoint",
                      shoot_frame_errors={"world": 1.45, "waypoint": 0.12})
    assert frame_text(res) == ("(in the waypoint frame: its paths' held-out error 0.12 against the world frame's 1.45, "
                               "as where a body's state has no world heading) ")
    assert frame_text(ProbeResult("both", None, {}, 0, 0.0, "r", shoot_frame="world")) == ""
    assert frame_text(ProbeResult("both", None, {}, 0, 0.0, "r")) == ""  # a probe from before: the world frame
