"""``shaped_es/actions.py``: the policy's [-1, 1] outputs as actions of each space it can act in and back, and a
choice-space body (MultiDiscrete, MultiBinary) trained, loaded and checked end to end."""

import gymnasium as gym
import numpy as np
import pytest

import shaped_es
from shaped_es.actions import (_to_env_action, action_map, action_problem, flat_hint, from_space, is_choice,
                               output_width, random_action, to_space, zero_action)

MD = gym.spaces.MultiDiscrete([3, 2, 4], start=[-1, 0, 2])
MB = gym.spaces.MultiBinary(5)
SPACES = [gym.spaces.Box(-2.0, 3.0, (2,), np.float32), gym.spaces.Discrete(4, start=1), MD, MB]


def test_the_policy_output_width_of_each_space():
    assert [output_width(s) for s in SPACES] == [2, 4, 9, 5]
    assert [is_choice(s) for s in SPACES] == [False, True, True, True]
    for unusable in (gym.spaces.Box(-1, 1, (2, 2)), gym.spaces.MultiDiscrete([[2, 3], [2, 2]]),
                     gym.spaces.MultiBinary([2, 2]), gym.spaces.Tuple((gym.spaces.Discrete(2),))):
        assert output_width(unusable) is None


def test_a_space_of_several_axes_is_told_the_flat_shape_to_declare():
    """A new user's Box (2, 1) was refused without the way round: declare it flat, reshape inside step."""
    assert flat_hint(gym.spaces.Box(-1, 1, (2, 1))) == ("; declare it of shape (2,) and reshape inside step: "
                                                        "action = np.reshape(action, (2, 1))")
    assert "shape (4,)" in flat_hint(gym.spaces.MultiBinary([2, 2]))
    assert "shape (4,)" in flat_hint(gym.spaces.MultiDiscrete([[2, 3], [2, 2]]))
    assert "shape (1,)" in flat_hint(gym.spaces.Box(-1, 1, ()))  # a scalar Box: np.reshape(action, ())
    assert [flat_hint(s) for s in (*SPACES, gym.spaces.Tuple((gym.spaces.Discrete(2),)))] == [""] * 5


def test_a_multidiscrete_output_is_an_argmax_per_sub_action():
    a = np.array([[0.1, 0.9, -0.2, 0.3, -0.3, -1.0, -1.0, 0.5, 0.0],
                  [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]], np.float32)  # (2, 3 + 2 + 4)
    got = to_space(MD, a)
    assert got.shape == (2, 3) and got.dtype == MD.dtype
    np.testing.assert_array_equal(got, [[0, 0, 4], [-1, 0, 2]])  # argmax + start; zeros: each sub-action's first
    assert MD.contains(got[0]) and MD.contains(got[1])


def test_a_multibinary_output_sets_a_bit_where_it_is_positive():
    got = to_space(MB, np.array([0.3, -0.3, 0.0, 1.0, -1e-6], np.float32))
    np.testing.assert_array_equal(got, [1, 0, 0, 1, 0])
    assert got.dtype == MB.dtype and MB.contains(got)


@pytest.mark.parametrize("space", SPACES, ids=lambda s: type(s).__name__)
def test_from_space_inverts_to_space_and_each_mapping_agrees(space):
    """A controller's action recorded as a label (from_space) maps back to itself; the rollouts' per-step map is
    the batch map; a random action lies in the space; a zero output is the middle of a Box, action 0 of a choice."""
    rng = np.random.default_rng(0)
    f = action_map(space)
    for _ in range(40):
        act = random_action(space, rng)
        assert space.contains(np.asarray(act, space.dtype) if not isinstance(space, gym.spaces.Discrete) else act)
        out = from_space(space, act)
        assert out.shape == (output_width(space),) and out.dtype == np.float32 and np.abs(out).max() <= 1
        np.testing.assert_allclose(np.asarray(_to_env_action(space, out), np.float64), np.asarray(act, np.float64),
                                   atol=1e-6)
        x = rng.uniform(-1.5, 1.5, output_width(space)).astype(np.float32)
        want, got = _to_env_action(space, x), f(x)
        assert type(got) is type(want) and np.asarray(got).dtype == np.asarray(want).dtype
        np.testing.assert_array_equal(got, want)
    zero = np.asarray(zero_action(space), np.float64)
    expected = {"Box": [0.5, 0.5], "Discrete": 1, "MultiDiscrete": [-1, 0, 2], "MultiBinary": [0] * 5}
    np.testing.assert_array_equal(zero, expected[type(space).__name__])


def test_what_makes_a_controllers_return_no_action():
    """A new user's gear 3 of MultiDiscrete([3, 5]) became "straight and gentle left" labels, silently."""
    md = gym.spaces.MultiDiscrete([3, 5])
    assert action_problem(md, [3, 0]) == "sub-action 0's 3 is outside 0..2"
    assert action_problem(MD, [-1, 1, 6]) == "sub-action 2's 6 is outside 2..5"  # start [-1, 0, 2]
    assert action_problem(md, [0, 3, 0]) == "3 values, the space takes 2"
    assert action_problem(md, 3) == "1 value, the space takes 2"
    assert action_problem(md, [1.5, 2]) == "a value that is not a whole number"
    assert action_problem(gym.spaces.Discrete(4, start=1), 0) == "0 is outside 1..4"
    assert action_problem(MB, [2, 0, 0, 0, 0]) == "a value other than 0 or 1"
    assert action_problem(SPACES[0], [np.nan, 0]) == "a non-finite value"
    assert action_problem(SPACES[0], "ab") == "str, not numbers"
    for ok, space in ((np.array([2.0, 1.0]), md), ([True, False, True, False, True], MB), (np.int64(4), SPACES[1]),
                      ([5.0, -9.0], SPACES[0])):  # floats of whole numbers, bools; a Box beyond its bounds is clipped
        assert action_problem(space, ok) is None


class _GridMD(gym.Env):
    """A point moved 0.1 a step along each axis by MultiDiscrete([3, 3]) (0 stays, 1 +, 2 -) towards a goal, or
    pushed by four on/off thrusters (MultiBinary(4): +x, -x, +y, -y), with the two-key contract and a controller."""

    observation_space = gym.spaces.Box(-5, 5, (4,), np.float32)
    action_space = gym.spaces.MultiDiscrete([3, 3])
    SIGN = np.array([0.0, 1.0, -1.0], np.float32)

    def _out(self):
        d = self.goal - self.pos
        wp = self.pos + d * min(1.0, 0.1 / max(float(np.linalg.norm(d)), 1e-6))
        return np.concatenate([self.pos, d]).astype(np.float32), {"position": self.pos.copy(), "waypoint": wp}

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.pos, self.goal = (self.np_random.uniform(-1, 1, 2).astype(np.float32) for _ in range(2))
        return self._out()

    def _move(self, action):
        return self.SIGN[np.asarray(action)] * 0.1

    def step(self, action):
        before = float(np.linalg.norm(self.goal - self.pos))
        self.pos = (self.pos + self._move(action)).astype(np.float32)
        obs, info = self._out()
        return obs, before - float(np.linalg.norm(self.goal - self.pos)), False, False, info

    def waypoint_controller(self, obs, info):
        d = info["waypoint"] - info["position"]
        return np.where(np.abs(d) < 0.05, 0, np.where(d > 0, 1, 2))


class _Thrusters(_GridMD):
    action_space = gym.spaces.MultiBinary(4)

    def _move(self, action):
        a = np.asarray(action, np.float32)
        return np.array([a[0] - a[1], a[2] - a[3]], np.float32) * 0.1

    def waypoint_controller(self, obs, info):
        d = info["waypoint"] - info["position"]
        return (np.array([d[0] > 0.05, d[0] < -0.05, d[1] > 0.05, d[1] < -0.05])).astype(np.int8)


class _GearOutOfRange(_GridMD):
    def waypoint_controller(self, obs, info):
        return np.array([3, 0])  # a choice past nvec: 3 of 3


gym.register("ActionsTest-GridMD-v0", entry_point=_GridMD, max_episode_steps=25)
gym.register("ActionsTest-GearOutOfRange-v0", entry_point=_GearOutOfRange, max_episode_steps=25)
gym.register("ActionsTest-Thrusters-v0", entry_point=_Thrusters, max_episode_steps=25)


@pytest.mark.parametrize("env_id, labels", [("ActionsTest-GridMD-v0", "controller"),
                                            ("ActionsTest-Thrusters-v0", "mphi")])
def test_a_choice_space_body_trains_shaped_and_loads(tmp_path, env_id, labels):
    """MultiDiscrete and MultiBinary bodies were refused in one line by every method; now a shaped run (its label
    probe with the learned labels; the controller's actions recorded as labels) trains, and the saved policy's
    predict and to_torch give the same actions, in the space."""
    cfg = {"env": env_id, "method": "shaped", "executor": "inline", "generations": 2, "seed": 0,
           "es": {"pairs": 4}, "policy": {"hidden": [8]}, "rollout": {"episodes": 1, "test_episodes": 2},
           "tensorboard": False, "shaping.labels": labels}
    rows = shaped_es.train(cfg, tmp_path / "r")
    assert len(rows) == 2 and all(np.isfinite(r["test_reward_mean"]) for r in rows)
    policy = shaped_es.load_policy(tmp_path / "r")
    env = policy.make_env()
    obs = np.stack([env.reset(seed=s)[0] for s in range(16)])  # (16, 4)
    acts = policy.predict(obs)  # (16, k) or (16, n)
    assert all(env.action_space.contains(a) for a in acts)
    torch = pytest.importorskip("torch")
    np.testing.assert_array_equal(policy.to_torch()(torch.as_tensor(obs)).numpy(), acts)
    assert env.action_space.contains(policy.predict(obs[0]))


def test_check_env_says_how_a_choice_space_is_acted_in():
    from shaped_es.cli.check_env import check_env

    grid = next(c for c in check_env("ActionsTest-GridMD-v0") if c.name == "spaces")
    assert grid.status == "ok" and "MultiDiscrete([3 3]) (an argmax per sub-action: 6 policy outputs; a zero " \
                                   "output is action [0 0])" in grid.detail
    bits = next(c for c in check_env("ActionsTest-Thrusters-v0") if c.name == "spaces")
    assert "MultiBinary(4) (a bit set per positive output: 4 policy outputs; a zero output sets no bit)" in bits.detail
    ctl = next(c for c in check_env("ActionsTest-Thrusters-v0") if c.name == "controller")
    assert "returns over " in ctl.detail and ", zero action 0.00" in ctl.detail


def test_a_controller_that_returns_no_action_stops_the_run_in_one_line_and_check_env_warns(tmp_path):
    from shaped_es.cli.check_env import check_env
    from shaped_es.env_probe import EnvError

    cfg = {"env": "ActionsTest-GearOutOfRange-v0", "method": "shaped", "executor": "inline", "generations": 1,
           "seed": 0, "es": {"pairs": 2}, "policy": {"hidden": [4]}, "rollout": {"episodes": 1, "test_episodes": 1},
           "tensorboard": False, "shaping.labels": "controller"}
    with pytest.raises(EnvError, match=r"^env 'ActionsTest-GearOutOfRange-v0': its waypoint_controller returned "
                                       r"\[3 0\], not an action of MultiDiscrete\(\[3 3\]\) \(sub-action 0's 3 is "
                                       r"outside 0\.\.2\) \(generation 1, episode seed \d+, step 0\)"):
        shaped_es.train(cfg, tmp_path / "r")
    ctl = next(c for c in check_env("ActionsTest-GearOutOfRange-v0") if c.name == "controller")
    assert ctl.status == "warn" and "it returned [3 0], not an action of MultiDiscrete([3 3]) (sub-action 0's 3 " \
                                   "is outside 0..2; seed 0, step 0)" in ctl.detail
