"""``env_check``: what an env needs to train here, one check per requirement, on envs that meet it and on
envs that break one requirement each."""

import re

import gymnasium as gym
import numpy as np
import pytest

from shaped_es.cli.check_env import FAIL, NO, OK, WARN, check_env, trains_with


class Point(gym.Env):
    """A point pushed towards the origin; misbehaves as ``flaw`` says."""

    observation_space = gym.spaces.Box(-10, 10, (2,), np.float32)
    action_space = gym.spaces.Box(-1, 1, (2,), np.float32)

    def __init__(self, flaw: str = "none"):
        self.flaw = flaw
        if flaw == "wide_actions":  # torques in [-2, 2], as Pusher-v5's: the policy's [-1, 1] is rescaled
            self.action_space = gym.spaces.Box(-2, 2, (2,), np.float32)
        if flaw == "unbounded":
            self.action_space = gym.spaces.Box(-np.inf, np.inf, (2,), np.float32)
        if flaw == "thrust_steer":  # thrust in [0, 5], steering in [-0.3, 0.3]
            self.action_space = gym.spaces.Box(np.array([0, -0.3], np.float32), np.array([5, 0.3], np.float32))
        if flaw == "obs_space_wrong":  # declares 3 floats, returns 2 (a new user's arm: 26 declared, 23 returned)
            self.observation_space = gym.spaces.Box(-10, 10, (3,), np.float32)
        if flaw == "offset":  # a third component at 1e4 (a user's raw sensor offset)
            self.observation_space = gym.spaces.Box(-1e5, 1e5, (3,), np.float32)
        self.calls = 0
        self.episodes = 0  # the "stateful" flaw: a count carried from one episode to the next

    def _info(self):
        if self.flaw == "no_waypoints" or (self.flaw == "some_waypoints" and self.t % 2):
            return {}
        if self.flaw == "waypoints_typo":
            return {"position": self.x.copy(), "waypoints": np.zeros(2, np.float32)}
        if self.flaw == "waypoint_3d":
            return {"position": self.x.copy(), "waypoint": np.zeros(3, np.float32)}
        if self.flaw == "column_waypoints":  # (2, 1) columns, a NumPy habit: rollouts read them flattened
            return {"position": self.x.reshape(2, 1), "waypoint": np.zeros((2, 1), np.float32)}
        if self.flaw == "static_position":  # the reset's position every step
            return {"position": self.x0.copy(), "waypoint": np.zeros(2, np.float32)}
        if self.flaw == "relative_waypoint":  # the waypoint (the origin) given relative to the body
            return {"position": self.x.copy(), "waypoint": -self.x.copy()}
        return {"position": self.x.copy(), "waypoint": np.zeros(2, np.float32)}

    def _obs(self):
        if self.flaw == "offset":
            return np.append(self.x, 1e4).astype(np.float32)
        if self.flaw == "stateful":  # as a NormalizeObservation wrapper's running statistics would
            return (self.x + 0.01 * self.episodes).astype(np.float32)
        return self.x.copy()

    def reset(self, *, seed=None, options=None):
        super().reset(seed=None if self.flaw == "unseeded" else seed)
        self.x, self.t = self.np_random.uniform(-1, 1, 2).astype(np.float32), 0
        self.x0, self.episodes = self.x.copy(), self.episodes + 1
        return self._obs(), self._info()

    def step(self, action):
        self.x = np.clip(self.x + 0.1 * np.asarray(action, np.float32), -10, 10)
        self.t += 1
        reward = np.nan if self.flaw == "nan_reward" and self.t == 5 else -float(np.linalg.norm(self.x))
        # float64 observations from step (not reset): two distinct warnings of Gymnasium's checker
        obs = self.x.astype(np.float64) if self.flaw == "float64_step" else self._obs()
        return obs, reward, False, False, self._info()


for flaw in ("none", "no_waypoints", "some_waypoints", "unseeded", "nan_reward", "unbounded", "float64_step",
             "wide_actions", "column_waypoints", "thrust_steer", "waypoints_typo", "waypoint_3d", "stateful", "offset",
             "static_position", "relative_waypoint", "obs_space_wrong"):
    gym.register(f"CheckPoint-{flaw}-v0", entry_point=Point, kwargs={"flaw": flaw}, max_episode_steps=20)
gym.register("CheckPoint-nolimit-v0", entry_point=Point)


def _status(checks):
    return {c.name: c.status for c in checks}


def test_an_env_that_meets_everything_trains_with_every_method():
    checks = check_env("CheckPoint-none-v0")
    assert [c.name for c in checks] == ["gymnasium API", "spaces", "time limit", "threshold", "steps", "seeding",
                                        "scale", "waypoints", "controller"]
    assert set(_status(checks).values()) == {OK, NO}  # the controller and the threshold are optional
    assert _status(checks)["controller"] == NO and _status(checks)["threshold"] == NO
    assert trains_with(checks) == ["vanilla", "guided", "cmaes", "shaped", "shaped_cmaes", "ppo"]
    assert "(2-d)" in checks[-2].detail


@pytest.mark.parametrize("env_id", ["CarNav-v0", "UR5Reach-v0"])
def test_the_builtin_envs_meet_the_waypoint_contract(env_id):
    checks = check_env(env_id, episodes=1, max_steps=50)
    assert FAIL not in _status(checks).values() and "shaped" in trains_with(checks)
    assert _status(checks)["controller"] == OK  # both offer the oracle labels' scripted controller
    threshold = next(c for c in checks if c.name == "threshold")
    assert threshold.status == OK and threshold.detail.startswith({"CarNav-v0": "200, ", "UR5Reach-v0": "40, "}[env_id])


def test_each_of_gymnasiums_warnings_gets_its_own_line():
    """A new user's env had two of the checker's warnings and saw only the first, with "(+1 more)"."""
    checks = check_env("CheckPoint-float64_step-v0")
    api = [c for c in checks if c.name == "gymnasium API"]
    assert len(api) == 2 and {c.status for c in api} == {WARN}, api
    assert "dtype" in api[0].detail and "not within" in api[1].detail and "more" not in api[1].detail
    # infinite observation bounds (Gymnasium's MuJoCo envs, the built-in ones) and an action Box other than
    # [-1, 1] (the policy's output is rescaled to it) are not worth a warning here
    assert _status(check_env("CheckPoint-wide_actions-v0"))["gymnasium API"] == OK
    assert [c.status for c in check_env("CarNav-v0", episodes=1, max_steps=20) if c.name == "gymnasium API"] == [OK]
    assert "shaped" in trains_with(checks)  # warnings, not failures


ES_AND_PPO = ["vanilla", "guided", "cmaes", "ppo"]


@pytest.mark.parametrize("flaw, name, status, methods", [
    ("no_waypoints", "waypoints", NO, ES_AND_PPO),  # optional: every method but shaped
    ("some_waypoints", "waypoints", NO, ES_AND_PPO),  # only shaped reads them: "no" for it, not FAIL for all
    ("unseeded", "seeding", WARN, ["vanilla", "guided", "cmaes", "shaped", "shaped_cmaes", "ppo"]),  # no repro
    # a new user's edge envs: state carried across episodes (a NormalizeObservation wrapper), an observation offset
    # of 1e4, a position that never moves, a waypoint given as w - p: each trained wrongly behind an "ok"
    ("stateful", "seeding", WARN, ["vanilla", "guided", "cmaes", "shaped", "shaped_cmaes", "ppo"]),
    ("offset", "scale", WARN, ["vanilla", "guided", "cmaes", "shaped", "shaped_cmaes", "ppo"]),
    ("static_position", "waypoints", WARN, ES_AND_PPO),  # shaped runs, but its labels cannot move such a position
    ("relative_waypoint", "waypoints", WARN, ES_AND_PPO),
    ("nan_reward", "steps", FAIL, []),
    ("obs_space_wrong", "steps", FAIL, []),  # every method's rollouts refuse it
    ("unbounded", "spaces", FAIL, []),
])
def test_each_flaw_is_named_on_its_line(flaw, name, status, methods):
    checks = check_env(f"CheckPoint-{flaw}-v0")
    assert _status(checks)[name] == status, checks
    assert trains_with(checks) == methods


def test_the_waypoint_lines_name_the_call_and_the_shapes():
    """A new user's env lacked the keys at reset only, and another gave a 3-d waypoint to a 2-d position."""
    waypoints = next(c for c in check_env("CheckPoint-some_waypoints-v0") if c.name == "waypoints")
    assert waypoints.detail.startswith("info['position'] and info['waypoint'] missing from step 1 (the other calls have both")
    assert waypoints.detail.endswith(": --method shaped cannot use it; every other method trains (README: "
                                     "environment contract)")


def test_a_broken_contract_names_the_key_and_leaves_the_other_methods():
    """Three new users' slips: a 3-d waypoint beside a 2-d position read "cannot train here" while --method
    vanilla trained; 'waypoints' for 'waypoint' said only "no info['position'] / info['waypoint']"."""
    checks = check_env("CheckPoint-waypoint_3d-v0")
    waypoints = next(c for c in checks if c.name == "waypoints")
    assert waypoints.status == NO and "got position (2,), waypoint (3,): --method shaped cannot use it" in waypoints.detail
    assert trains_with(checks) == ES_AND_PPO
    typo = next(c for c in check_env("CheckPoint-waypoints_typo-v0") if c.name == "waypoints")
    assert typo.status == NO and typo.detail.startswith(
        "no info['waypoint'] (info['position'] is there; did you mean 'waypoints'?): every method but shaped")
    none = next(c for c in check_env("CheckPoint-no_waypoints-v0") if c.name == "waypoints")
    assert none.detail.startswith("no info['position'] / info['waypoint']: every method but shaped")


def test_action_bounds_are_shown_per_dimension_where_they_differ():
    spaces = {c.name: c.detail for c in check_env("CheckPoint-thrust_steer-v0")}["spaces"]
    assert "actions Box(2) in [0, 5] x [-0.3, 0.3] (the policy's [-1, 1] rescaled)" in spaces
    assert "actions Box(2) in [-2, 2] (" in {c.name: c.detail for c in check_env("CheckPoint-wide_actions-v0")}["spaces"]


def test_column_waypoints_pass_as_the_rollouts_read_them():
    """A (2, 1) position and waypoint: the rollouts read them flattened and train --method shaped ran; check-env
    said FAIL ("cannot train here") -- now it says ok and how they are read."""
    checks = check_env("CheckPoint-column_waypoints-v0")
    waypoints = next(c for c in checks if c.name == "waypoints")
    assert waypoints.status == OK and "(2-d, (2, 1) arrays read flattened)" in waypoints.detail
    assert "shaped" in trains_with(checks)


def test_a_probe_that_fails_names_the_probe_after_the_check_lines(tmp_path, capsys, monkeypatch):
    """check-env --labels on an env whose waypoint turns NaN mid-episode: the check lines print first (before,
    only the error did), and the error names the label probe (before: "generation 10000", its seed stream)."""
    from shaped_es.cli.commands import main

    class LateNaN(Point):
        def _info(self):
            info = super()._info()
            if self.t >= 25:  # after check-env's own random steps, inside the probe's episodes
                info["waypoint"] = np.full(2, np.nan, np.float32)
            return info

    gym.register("CheckPoint-latenan-v0", entry_point=LateNaN, max_episode_steps=40)
    monkeypatch.chdir(tmp_path)
    assert main(["check-env", "CheckPoint-latenan-v0", "--labels", "--max-steps", "20"]) != 0
    cap = capsys.readouterr()
    assert "ok    waypoints" in cap.out and "CheckPoint-latenan-v0 trains with:" in cap.out
    assert re.search(r"non-finite info\['waypoint'\] \(\[nan, nan\]\) \(the label probe, before generation 1, "
                     r"episode seed \d+, step 25\)", cap.err), cap.err


def test_no_time_limit_rules_out_ppo():
    checks = check_env("CheckPoint-nolimit-v0", max_steps=30)
    assert _status(checks)["time limit"] == WARN and "ppo" not in trains_with(checks)
    assert "vanilla" in trains_with(checks)


def test_the_threshold_line_is_benchmarks_at_the_kwargs_reward_scale():
    """A built-in env with a rescaled reward has no default threshold in benchmark; check-env says the same."""
    checks = check_env("CarNav-v0", {"step_penalty": 0.5}, episodes=1, max_steps=20)
    assert _status(checks)["threshold"] == NO


class SteeredPoint(Point):
    """The point with a scripted controller: straight to the origin (the waypoint)."""

    def waypoint_controller(self, obs, info):
        return np.clip(-10.0 * np.asarray(info["position"]), -1, 1).astype(np.float32)


class BrokenController(Point):
    def waypoint_controller(self, obs, info):
        raise RuntimeError("no gains set")


gym.register("CheckPoint-steered-v0", entry_point=SteeredPoint, max_episode_steps=20)
gym.register("CheckPoint-brokenctl-v0", entry_point=BrokenController, max_episode_steps=20)


def test_the_controller_line_says_what_it_returns_against_zero_and_random_actions():
    """A new user measured their controller's, zero action's and random actions' returns by hand to set a
    threshold; the controller's line gives them (rounds of 10 episodes each, seeds 0, 1, ..., within a few seconds)
    and 90% of the way from zero to it, with 2 standard errors (two new users' 10-episode thresholds were noisy)."""
    detail = next(c for c in check_env("CheckPoint-steered-v0") if c.name == "controller").detail
    n = int(detail.split("returns over ")[1].split(" episodes")[0])  # rounds of 10 within a time budget
    assert n % 10 == 0 and 10 <= n <= 50
    got = {k: float(v) for k, v in (p.rsplit(" ", 1) for p in
                                     detail.split(f"returns over {n} episodes: ")[1].split(" (a threshold")[0].split(", "))}
    assert set(got) == {"it", "zero action", "random actions"}
    assert got["it"] > got["zero action"] and got["it"] > got["random actions"]  # it steers to the origin
    env = gym.make("CheckPoint-steered-v0")  # zero action: the point stays; its return by hand, same seeds
    zeros = np.array([20 * -np.linalg.norm(env.reset(seed=s)[0]) for s in range(n)])
    assert got["zero action"] == pytest.approx(zeros.mean(), abs=0.01)
    assert f"a threshold: {got['zero action'] + 0.9 * (got['it'] - got['zero action']):.2f} +- " in detail
    assert "; +-: 2 standard errors over the episodes)" in detail
    broken = next(c for c in check_env("CheckPoint-brokenctl-v0") if c.name == "controller")
    assert broken.status == WARN and "it raised RuntimeError: no gains set" in broken.detail  # not "ok" (a new user's)
    assert broken.detail.startswith("waypoint_controller(obs, info) cannot drive the env as it is")


class DiscreteSteered(gym.Env):
    """Five moves (0 stays) towards the origin, with a controller: a Discrete body's controller line."""

    observation_space = gym.spaces.Box(-10, 10, (2,), np.float32)
    action_space = gym.spaces.Discrete(5)
    MOVES = np.array([[0, 0], [0.1, 0], [-0.1, 0], [0, 0.1], [0, -0.1]], np.float32)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.x = self.np_random.uniform(-1, 1, 2).astype(np.float32)
        return self.x.copy(), {"position": self.x.copy(), "waypoint": np.zeros(2, np.float32)}

    def step(self, action):
        self.x = self.x + self.MOVES[int(action)]
        return self.x.copy(), -float(np.linalg.norm(self.x)), False, False, {"position": self.x.copy(),
                                                                            "waypoint": np.zeros(2, np.float32)}

    def waypoint_controller(self, obs, info):
        i = int(np.argmax(np.abs(obs)))
        return (1 if obs[0] < 0 else 2) if i == 0 else (3 if obs[1] < 0 else 4)


gym.register("CheckPoint-discrete_steered-v0", entry_point=DiscreteSteered, max_episode_steps=20)


def test_the_controller_line_on_a_discrete_body():
    """A new user's grid: the controller's returns and a threshold were given for Box actions only, silently."""
    detail = next(c for c in check_env("CheckPoint-discrete_steered-v0") if c.name == "controller").detail
    assert "returns over " in detail and ", zero action " in detail and "(a threshold: " in detail


@pytest.mark.parametrize("flaw, needle", [
    ("stateful", "carries state from one episode to the next"),
    ("offset", "observation component 2 reaches 1e+04"),
    ("static_position", "info['position'] never moved"),
    ("relative_waypoint", "moved by minus the position's step on 100% of the moving steps"),
])
def test_the_new_warnings_say_what_they_saw(flaw, needle):
    assert any(needle in c.detail for c in check_env(f"CheckPoint-{flaw}-v0")), flaw
    checks = check_env("CheckPoint-none-v0")
    assert all(c.status == OK for c in checks if c.name in ("seeding", "scale", "waypoints"))
    # the scale line names its largest component (a new user's boat read "within +-8.59" and could not tell which)
    scale = next(c.detail for c in checks if c.name == "scale")
    assert re.search(r"within \+-\S+ \(the largest: component \d+\)", scale), scale


def test_a_run_warns_where_reset_ignores_its_seed():
    """check-env named an env whose reset ignores its seed, and a run said nothing: a second reset(seed=0) where the
    method reads the reset info (the shaped methods) tells, and the run says it once, before its first rollout."""
    import warnings

    from shaped_es.env_probe import probe_env
    from shaped_es.rollout import warn_if_unseeded

    assert probe_env("CheckPoint-unseeded-v0", reset=True).unseeded
    assert not probe_env("CheckPoint-none-v0", reset=True).unseeded
    assert not probe_env("CheckPoint-unseeded-v0").unseeded  # not probed without a reset
    with warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        warn_if_unseeded("CheckPoint-unseeded-v0", probe_env("CheckPoint-unseeded-v0", reset=True))
        warn_if_unseeded("CheckPoint-none-v0", probe_env("CheckPoint-none-v0", reset=True))
    assert len(got) == 1 and "it ignores the seed or carries state" in str(got[0].message)


def test_envs_listing_agrees_with_check_env():
    """``shaped-es envs`` listed a 3-d position beside a 2-d waypoint as "yes (3-d)" and an unbounded action space
    (a ClipAction wrapper) as usable, where check-env and a run refuse both."""
    from shaped_es.cli.describe_env import describe_env

    assert describe_env("CheckPoint-none-v0")["waypoints"] == 2
    assert describe_env("CheckPoint-waypoint_3d-v0")["waypoints"] is None
    unbounded = describe_env("CheckPoint-unbounded-v0")
    assert unbounded["error"] is not None and "unbounded action space" in unbounded["error"]
