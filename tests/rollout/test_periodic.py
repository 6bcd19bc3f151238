"""rollout/periodic.py: a waypoint position that wraps (a heading in (-pi, pi]) recorded continuous, each step and
w - p the short way; declared by the env or detected; nothing changes for a position that does not wrap."""

import math

import gymnasium as gym
import numpy as np
import pytest

from shaped_es.env_probe import EnvSpecError
from shaped_es.policies import MLPSpec
from shaped_es.rollout import RolloutTask, periodic, run_task

TAU = 2 * math.pi


class _Turn(gym.Env):
    """A turntable (angle rate control, 0.3 rad a step at full action) whose info position is its heading wrapped
    into [-pi, pi) (``wrapped``) or the unwrapped angle; the waypoint a quarter turn ahead; ``period``: what it
    declares (``"unset"``: no attribute)."""

    observation_space = gym.spaces.Box(-10.0, 10.0, (3,), np.float32)
    action_space = gym.spaces.Box(-1.0, 1.0, (1,), np.float32)

    def __init__(self, wrapped=True, period="unset"):
        self.wrapped = wrapped
        if period != "unset":
            self.position_period = period

    def _out(self):
        th = periodic.wrap(np.array([self.th]), np.array([TAU])) if self.wrapped else np.array([self.th])
        wp = th + math.pi / 2
        wp = periodic.wrap(wp, np.array([TAU])) if self.wrapped else wp
        obs = np.array([math.cos(self.th), math.sin(self.th), 0.0], np.float32)
        return obs, {"position": th, "waypoint": wp}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.th = float(self.np_random.uniform(-math.pi, math.pi))
        return self._out()

    def step(self, action):
        self.th += 0.3 * float(np.clip(action, -1, 1)[0])
        obs, info = self._out()
        return obs, 0.0, False, False, info


for _name, _kw in {"WrapTurn-v0": {}, "PlainTurn-v0": {"wrapped": False}, "WrapTurnOff-v0": {"period": None},
                   "WrapTurnDeclared-v0": {"period": [TAU]}, "WrapTurnBad-v0": {"period": "a turn"},
                   "WrapTurnDegrees-v0": {"period": 360.0}, "WrapTurnTwo-v0": {"period": [TAU, TAU]}}.items():
    gym.register(_name, entry_point=_Turn, kwargs=_kw, max_episode_steps=60)


class _Pendulum(_Turn):
    """A gravity pendulum (0: hanging) whose torque cannot hold it horizontal, its heading reported wrapped: the
    cut is at the top, which neither random actions nor a held torque reach; a torque that flips pumps it over."""

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.th, self.om = float(self.np_random.uniform(-0.3, 0.3)), 0.0
        return self._out()

    def step(self, action):
        self.om += 0.05 * (-10 * math.sin(self.th) + 5 * float(np.clip(action, -1, 1)[0]) - 0.1 * self.om)
        self.th += 0.05 * self.om
        obs, info = self._out()
        return obs, 0.0, False, False, info


gym.register("WrapPendulum-v0", entry_point=_Pendulum, max_episode_steps=200)


def test_detection_pumps_a_swing_over_the_top():
    np.testing.assert_array_equal(periodic.detect_env("WrapPendulum-v0", {}), [TAU])
    assert periodic.detect_env("PlainTurn-v0", {}) is None


def test_wrap_takes_each_periodic_coordinate_the_short_way():
    got = periodic.wrap(np.array([[6.2, 6.2], [-3.3, -3.3], [3.0, 3.0]]), np.array([TAU, 0.0]))
    np.testing.assert_allclose(got[:, 0], [6.2 - TAU, -3.3 + TAU, 3.0])
    np.testing.assert_array_equal(got[:, 1], [6.2, -3.3, 3.0])  # not periodic: as it is


def test_the_unwrapper_keeps_a_heading_continuous_across_the_cut():
    u = periodic.Unwrapper(np.array([TAU]))
    pos, wp = u.start(np.array([[3.1]]), np.array([[-3.1]]))  # the waypoint 0.08 ahead, across the cut
    np.testing.assert_allclose(wp, [[3.1 + (TAU - 6.2)]])
    p, w = u.step(0, np.array([-3.13]), np.array([-3.0]))  # crossed: +0.053, not -6.23
    np.testing.assert_allclose(p, [3.1 + (TAU - 6.23)])
    np.testing.assert_allclose(w - p, [0.13])


def _episodes(th0, rate, n, steps=50):
    rng = np.random.default_rng(0)
    eps = []
    for k in range(n):
        th = th0 + np.cumsum(np.full(steps, rate * (1 if k % 2 else -1)) + 0.01 * rng.standard_normal(steps))
        eps.append(th[:, None])
    return eps


def test_detect_finds_a_wrapped_heading_and_nothing_else():
    wrapped = [periodic.wrap(e, np.array([TAU])) for e in _episodes(0.0, 0.3, 4)]
    np.testing.assert_array_equal(periodic.detect(wrapped), [TAU])
    degrees = [np.degrees(periodic.wrap(e, np.array([TAU]))) for e in _episodes(0.0, 0.3, 4)]
    np.testing.assert_array_equal(periodic.detect(degrees), [360.0])
    assert periodic.detect(_episodes(0.0, 0.3, 4)) is None  # unwrapped: spans several turns, no jump
    # a 2-D point moving on [-pi, pi]^2 without jumps; a point that teleports by 2 pi once per episode but also
    # moves a long way in one step; a point whose values spread wider than a turn
    rng = np.random.default_rng(1)
    walk = [np.clip(np.cumsum(0.05 * rng.standard_normal((80, 2)), axis=0), -math.pi, math.pi) for _ in range(4)]
    assert periodic.detect(walk) is None
    jumpy = [np.concatenate([e[:20], e[20:] + TAU * 0.9, e[-1:] + 2.0]) for e in _episodes(0.0, 0.01, 4)]
    assert periodic.detect(jumpy) is None
    # a heading beside a position that does not wrap: only its coordinate
    both = [np.concatenate([periodic.wrap(e, np.array([TAU])), 0.01 * np.arange(len(e))[:, None]], axis=1)
            for e in _episodes(0.0, 0.3, 4)]
    np.testing.assert_array_equal(periodic.detect(both), [TAU, 0.0])
    # recorded rows (a generation's, episodes one after another, a lone row among them) give what detect gives
    for eps in (wrapped, degrees, walk, jumpy, both):
        rows = [e.reshape(len(e), -1) for e in eps] + [np.full((1, eps[0].reshape(len(eps[0]), -1).shape[1]), 9.0)]
        follows = np.concatenate([np.r_[np.ones(len(r) - 1, bool), False] for r in rows])  # (N,)
        got, want = periodic.detect_recorded(np.concatenate(rows), follows), periodic.detect(eps)
        assert (got is None and want is None) or np.array_equal(got, want)


def test_declared_periods_and_a_bad_one_in_one_line():
    assert periodic.declared(gym.make("WrapTurnOff-v0"), 1) is None
    np.testing.assert_array_equal(periodic.declared(gym.make("WrapTurnDeclared-v0"), 1), [TAU])
    with pytest.raises(EnvSpecError, match=r"position_period = 'a turn' \(not a number\): give one period"):
        periodic.declared(gym.make("WrapTurnBad-v0"), 1)
    from shaped_es.config import build_config
    from shaped_es.guides.shaped_setup import check_period

    with pytest.raises(EnvSpecError, match=r"\(2 periods for 1 coordinates\)"):
        periodic.declared(gym.make("WrapTurnTwo-v0"), 1)
    with pytest.raises(EnvSpecError, match="give one period"):  # the shaped preflight: before the run directory
        check_period(build_config({"env": "WrapTurnBad-v0", "method": "shaped"}), 1)
    check_period(build_config({"env": "WrapTurnDeclared-v0", "method": "shaped"}), 1)


def test_wrap_text_is_check_envs_and_the_runs_one_line():
    assert periodic.wrap_text(None, False) == ""
    assert periodic.wrap_text(np.array([TAU, 0.0]), False) == (
        "info['position'] wraps ([0] at 2 pi; detected from random-action episodes): shaped runs record it "
        "continuous and take each step and w - p the short way (declare env.unwrapped.position_period to say so "
        "yourself, None if it does not wrap)")
    assert periodic.wrap_text(np.array([360.0]), True) == (  # declared: no hint
        "info['position'] wraps ([0] at 360; the env's position_period): shaped runs record it continuous and take "
        "each step and w - p the short way")


def test_a_runs_start_makes_one_env_for_the_declared_period(monkeypatch):
    """preflight's check_period reads the declaration; the guide's wrap_line takes it from there."""
    from shaped_es.config import build_config
    from shaped_es.guides.shaped_setup import check_period, wrap_line

    made = []
    make = periodic.make_env
    monkeypatch.setattr(periodic, "make_env", lambda *a: made.append(a) or make(*a))
    monkeypatch.setattr(periodic, "_DECLARATIONS", {})
    monkeypatch.setattr(periodic, "_CACHE", {})
    cfg = build_config({"env": "WrapTurnDeclared-v0", "method": "shaped"})
    check_period(cfg, 1)
    line, declared, period = wrap_line(cfg, 1)
    assert len(made) == 1 and declared and line == periodic.wrap_text(np.array([TAU]), True)
    np.testing.assert_array_equal(period, [TAU])


def _recorded(env_id):
    spec = MLPSpec(3, 1, (4,))
    params = (spec.init(0) + 0.5).astype(np.float32)[None]  # (1, n): turns steadily, across the cut
    res = run_task(RolloutTask(env_id, {}, spec, params, np.arange(1), np.array([[3, 4]]), record=True))
    return res.transitions[0]


def test_a_wrapped_heading_is_recorded_as_the_unwrapped_one():
    """The recorded steps and w - p of a heading reported wrapped (detected, or declared) equal those of the same
    body reporting its unwrapped angle; declared None records the jumps as they come."""
    plain, wrapped, declared, off = (_recorded(i) for i in ("PlainTurn-v0", "WrapTurn-v0", "WrapTurnDeclared-v0",
                                                             "WrapTurnOff-v0"))
    steps = np.diff(plain.position, axis=0)  # (T-1, 1), episode boundary row included
    assert np.abs(steps).max() > 0.05  # it turns
    for tr in (wrapped, declared):
        np.testing.assert_allclose(np.diff(tr.position, axis=0), steps, atol=1e-5)
        np.testing.assert_allclose(tr.waypoint - tr.position, plain.waypoint - plain.position, atol=1e-5)
    # the episode boundary aside, declared None keeps the wrapped heading's ~2 pi jumps (the old recording)
    assert (np.abs(np.diff(off.position, axis=0)) > 5.0).sum() > (np.abs(steps) > 5.0).sum()


def test_the_label_probes_live_queries_take_the_short_way(monkeypatch):
    """label_probe.drive asks the labels for w - p as the recorded rollouts have it: the short way."""
    from shaped_es.config import build_config
    from shaped_es.guides import label_probe

    cfg = build_config({"env": "WrapTurn-v0", "method": "shaped"})
    seen = []

    def label(s, q):
        seen.append(float(q[0, 0]))
        return np.ones((s.shape[0], 1), np.float32)

    label_probe.drive(cfg, label, "world", np.array([5]))
    assert len(seen) > 20 and max(abs(x) for x in seen) == pytest.approx(math.pi / 2, abs=1e-6)


def test_check_env_says_a_heading_wraps_and_refuses_a_bad_period():
    from shaped_es.cli.check_env import check_env

    line = {c.name: c for c in check_env("WrapTurn-v0")}["waypoints"]
    assert line.status == "ok" and "info['position'] wraps ([0] at 2 pi; detected from random-action episodes)" \
        in line.detail and "declare env.unwrapped.position_period" in line.detail
    assert "wraps" not in {c.name: c for c in check_env("PlainTurn-v0")}["waypoints"].detail
    assert "wraps ([0] at 2 pi; the env's position_period)" in {c.name: c for c in check_env(
        "WrapTurnDeclared-v0")}["waypoints"].detail
    bad = {c.name: c for c in check_env("WrapTurnBad-v0")}["waypoints"]
    assert bad.status == "no" and bad.detail.startswith("position_period = 'a turn' (not a number): give one")
    assert bad.detail.endswith("--method shaped refuses it; every other method trains")
    # well-formed but wrong (a new user's radians declared as 360; None on a heading that jumps): a warning
    for env_id in ("WrapTurnDegrees-v0", "WrapTurnOff-v0"):
        odd = {c.name: c for c in check_env(env_id)}["waypoints"]
        assert odd.status == "warn" and odd.detail.endswith(
            "but random-action episodes jump by about a turn ([0] at 2 pi): check env.unwrapped.position_period")


def test_a_wrap_the_start_missed_is_taken_from_the_next_rollouts_and_a_detected_one_is_unwrapped(
        tmp_path, monkeypatch, capsys):
    """A shaped run on the wrapped turntable: detected at the start, its first line says so and the recorded
    rows do not jump; where the start's random-action episodes miss the wrap (a pendulum only a trained policy
    takes over the cut; simulated by a detection that finds nothing), the first generation whose rows jump by a
    turn says so in one line and the rollouts after it record the heading continuous (the run folder says from
    which generation; a resumed run keeps it); a declared period that leaves the jumps in (360 for radians) is
    the env's word: one warning line naming position_period."""
    from helpers import train

    from shaped_es.shaping.trajectories import read_generation

    base = {"method": "shaped", "generations": 2, "executor": "inline", "es": {"pairs": 4},
            "shaping": {"inverse_dynamics": {"frame": "world"}}}
    train(tmp_path / "found", {**base, "env": "WrapTurn-v0"})
    err = capsys.readouterr().err
    assert "info['position'] wraps ([0] at 2 pi; detected from random-action episodes)" in err
    assert "warning" not in err
    from shaped_es.guides.shaped_setup import read_wrap_file  # the run folder says so (the final JSON reads it)

    assert read_wrap_file(tmp_path / "found") == {"position_period": [TAU], "source": "detected"}
    monkeypatch.setattr(periodic, "_CACHE", {})
    monkeypatch.setattr(periodic, "detect_env", lambda env_id, kwargs: None)
    store = train(tmp_path / "missed", {**base, "env": "WrapTurn-v0", "generations": 4})
    err = capsys.readouterr().err
    assert err.count("'s recorded info['position'] wraps") == 1 and "recorded info['position'] wraps ([0] at 2 pi; " \
        "not seen by the start of the run): the next rollouts record it continuous" in err
    first = int(err.split("generation ")[-1].split("'s recorded")[0]) - 1  # the line counts from 1, the file from 0
    assert read_wrap_file(tmp_path / "missed") == {"position_period": [TAU], "source": "detected",
                                                   "generation": first}
    from shaped_es.config import build_config
    from shaped_es.trainer import Trainer

    Trainer(build_config({**base, "env": "WrapTurn-v0", "generations": 6}), store, progress=False).run()  # resumed
    assert "recorded info['position'] wraps" not in capsys.readouterr().err
    jumps = []
    for g in range(6):
        steps = [np.abs(t.next_position()[1] - t.position)[t.next_position()[0]]  # (T', 1) within episodes
                 for t in read_generation(store.trajectories_dir, g)]
        jumps.append(int((np.concatenate(steps) > 5.0).sum()))
    assert jumps[first] >= 2 and sum(jumps[first + 2:]) == 0 and first + 2 < 4, jumps  # continuous from g + 2 on

    monkeypatch.undo()
    train(tmp_path / "degrees", {**base, "env": "WrapTurnDegrees-v0"})  # declared, wrong: its rows still jump
    err = capsys.readouterr().err
    assert err.count("warning: generation") == 1 and "([0] at 2 pi; the env's position_period leaves it out)" in err \
        and "check env.unwrapped.position_period" in err
