import numpy as np
import pytest

from shaped_es.policies import MLPSpec, forward
from shaped_es.rollout import EnvSpecError, RolloutTask, make_env, run_task


def _task(record=False, seeds=((1, 2), (1, 2), (3, 4))):
    spec = MLPSpec(4, 2, (8,))
    P = np.stack([spec.init(i) for i in range(len(seeds))])
    return RolloutTask("CartPole-v1", {}, spec, P, np.arange(len(seeds)), np.array(seeds), record=record)


def test_rollout_deterministic_and_chunk_independent():
    full = run_task(_task())
    again = run_task(_task())
    np.testing.assert_array_equal(full.returns, again.returns)
    # member 0 alone gives the same returns as inside the chunk
    t = _task()
    t.params, t.members, t.seeds = t.params[:1], t.members[:1], t.seeds[:1]
    np.testing.assert_array_equal(run_task(t).returns[0], full.returns[0])
    # CartPole pays +1 per step: returns equal lengths
    np.testing.assert_array_equal(full.returns, full.lengths)


def test_rollout_records_transitions():
    res = run_task(_task(record=True))
    assert len(res.transitions) == 3
    tr = res.transitions[1]
    assert len(tr) == res.lengths[1].sum()
    np.testing.assert_allclose(tr.episode_returns(), res.returns[1])
    assert tr.state.shape == (len(tr), 4) and tr.action.shape == (len(tr), 2)
    assert tr.position.shape == (len(tr), 0)  # CartPole does not carry the waypoint contract


def test_unknown_env_one_line():
    for bad in ("NoSuchEnv-v0", "no_such_module:Foo-v0"):
        with pytest.raises(EnvSpecError) as e:
            make_env(bad)
        assert "\n" not in str(e.value)
    with pytest.raises(EnvSpecError, match=r"an own env is named module:Id, e.g. --env mymodule:NoSuchEnv-v0"):
        make_env("NoSuchEnv-v0")
    # a new user wrote a dot where the colon goes: the example is their module and id
    with pytest.raises(EnvSpecError, match=r"e.g. --env forcepoint:ForcePoint-v0, and its module registers it"):
        make_env("forcepoint.ForcePoint-v0")


def test_a_record_mask_keeps_those_members_and_the_rest_is_unchanged():
    spec = MLPSpec(13, 5, (8,))
    P = np.stack([spec.init(i) for i in range(3)])
    seeds = np.array([[1, 2]] * 3)
    full = run_task(RolloutTask("shaped_es:UR5Reach-v0", {}, spec, P, np.arange(3), seeds, record=True,
                                max_steps=20))
    part = run_task(RolloutTask("shaped_es:UR5Reach-v0", {}, spec, P, np.arange(3), seeds,
                                record=np.array([True, False, True]), max_steps=20))
    np.testing.assert_array_equal(part.returns, full.returns)
    assert [t.member for t in part.transitions] == [0, 2]
    for a, b in zip(part.transitions, [full.transitions[0], full.transitions[2]]):
        np.testing.assert_array_equal(a.state, b.state)
        np.testing.assert_array_equal(a.action, b.action)
        assert a.expert is None  # not asked for


def test_expert_actions_are_the_controllers_on_the_recorded_states():
    from shaped_es.envs.ur5.config import make_config
    from shaped_es.envs.ur5.controller import waypoint_controller

    spec = MLPSpec(13, 5, (8,))
    P = np.stack([spec.init(i) for i in range(2)])
    res = run_task(RolloutTask("shaped_es:UR5Reach-v0", {}, spec, P, np.arange(2), np.array([[3, 4]] * 2),
                               record=True, max_steps=15, expert=True))
    for tr in res.transitions:  # UR5's controller reads only what a transition records
        np.testing.assert_allclose(tr.expert, waypoint_controller(make_config(), tr.state, tr.position,
                                                                  tr.waypoint), atol=1e-6)


def test_expert_actions_of_a_plain_gym_env_are_mapped_to_the_policy_scale():
    """A 1-D point with the waypoint contract, an action Box(-2, 2) and a controller (the gym path)."""
    import gymnasium as gym

    class Point(gym.Env):
        observation_space = gym.spaces.Box(-10, 10, (1,), np.float32)
        action_space = gym.spaces.Box(-2.0, 2.0, (1,), np.float32)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            self.x, self.t = 0.0, 0
            return np.array([self.x], np.float32), self._info()

        def _info(self):
            return {"position": np.array([self.x]), "waypoint": np.array([self.x + 1.0])}

        def step(self, a):
            self.x += float(a[0]) * 0.1
            self.t += 1
            return np.array([self.x], np.float32), -1.0, False, self.t >= 5, self._info()

        def waypoint_controller(self, obs, info):
            return np.array([1.0], np.float32)  # half of the action range up

    gym.register("PointCtl-v0", entry_point=Point)
    spec = MLPSpec(1, 1, (4,))
    res = run_task(RolloutTask("PointCtl-v0", {}, spec, spec.init(0)[None], np.arange(1), np.array([[0]]),
                               record=True, expert=True))
    np.testing.assert_allclose(res.transitions[0].expert, 0.5)  # 1.0 in [-2, 2] is 0.5 in [-1, 1]
    with pytest.raises(EnvSpecError, match="waypoint_controller"):
        run_task(RolloutTask("CartPole-v1", {}, MLPSpec(4, 2, (4,)), MLPSpec(4, 2, (4,)).init(0)[None],
                             np.arange(1), np.array([[0]]), record=True, expert=True))


def test_actions_map_to_the_space():
    """Policy outputs in [-1, 1] map to a Box's bounds, exactly the output itself for a [-1, 1] Box (the
    built-in envs: their batched cores take the raw output, their Gymnasium envs the mapped one);
    Discrete takes the argmax, offset by the space's start."""
    import gymnasium as gym

    from shaped_es.rollout import _to_env_action, to_space

    a = np.random.default_rng(0).uniform(-1, 1, (50, 2)).astype(np.float32)
    a[0] = [1e-9, -3e-8]  # tiny outputs: (a + 1) - 1 would round them away
    np.testing.assert_array_equal(to_space(gym.spaces.Box(-1.0, 1.0, (2,), np.float32), a), a)
    box = gym.spaces.Box(np.array([-2.0, 0.0], np.float32), np.array([2.0, 10.0], np.float32))
    got = to_space(box, np.array([[-1.0, -1.0], [0.0, 0.5], [1.0, 1.0]], np.float32))
    np.testing.assert_allclose(got, [[-2.0, 0.0], [0.0, 7.5], [2.0, 10.0]])
    np.testing.assert_array_equal(_to_env_action(box, a[3]), to_space(box, a[3:4])[0])
    disc = gym.spaces.Discrete(3, start=-1)
    assert _to_env_action(disc, np.array([0.1, 0.9, -0.2])) == 0
    np.testing.assert_array_equal(to_space(disc, np.array([[0.1, 0.9, -0.2], [1.0, 0.0, 0.0]])), [0, -1])


def test_a_rollouts_action_map_is_the_spaces_mapping_bit_for_bit():
    """actions.action_map (the bounds' arithmetic done once per rollout) gives what _to_env_action gives,
    value, dtype and type, on [-1, 1], asymmetric and float64 Boxes and a Discrete space."""
    import gymnasium as gym

    from shaped_es.actions import _to_env_action, action_map

    rng = np.random.default_rng(0)
    spaces = [gym.spaces.Box(-1.0, 1.0, (6,), np.float32), gym.spaces.Box(-3.0, 5.0, (3,), np.float32),
              gym.spaces.Box(np.array([0.0, -2.0]), np.array([1.0, 2.0]), dtype=np.float64),
              gym.spaces.Discrete(4, start=1)]
    for space in spaces:
        f = action_map(space)
        for _ in range(50):
            a = rng.uniform(-1.5, 1.5, space.shape[0] if space.shape else 4).astype(np.float32)
            want, got = _to_env_action(space, a), f(a)
            assert type(got) is type(want) and np.asarray(got).dtype == np.asarray(want).dtype
            np.testing.assert_array_equal(got, want)


def test_the_waypoint_pairs_fast_path_is_the_checked_one():
    """env_probe.waypoint_pair(finite=False), a recorded rollout's per-step read, gives the checked read's arrays;
    a non-finite pair then fails the rollout's one check per step with the checked read's message."""
    from shaped_es.env_probe import BadOutput, waypoint_pair
    from shaped_es.rollout.checks import _check_pairs

    info = {"position": np.array([1.5, -2.0]), "waypoint": np.array([3.0, 1e-9])}
    for fast, checked in zip(waypoint_pair(info, 2, finite=False), waypoint_pair(info, 2)):
        assert fast.dtype == checked.dtype == np.float32
        np.testing.assert_array_equal(fast, checked)
    bad = {"position": np.array([1.5, np.nan]), "waypoint": np.array([3.0, 0.0])}
    pos, wp = (np.stack(x) for x in zip(waypoint_pair(info, 2, False), waypoint_pair(bad, 2, False)))  # (2, 2)
    with pytest.raises(BadOutput, match=r"a non-finite info\['position'\]"):
        waypoint_pair(bad, 2)
    task = RolloutTask("CarNav-v0", {}, MLPSpec(4, 2, (4,)), np.zeros((1, 1)), np.arange(1), np.array([[7, 8]]),
                       generation=3)
    with pytest.raises(Exception, match=r"a non-finite info\['position'\].*episode seed 8, step 5"):
        _check_pairs(task, pos, wp, [info, bad], [7, 8], 5)
    _check_pairs(task, pos[:1], wp[:1], [info], [7], 5)  # finite: nothing


@pytest.mark.parametrize("env_id, spec, expert", [("CarNav-v0", None, False),
                                                   ("shaped_es:UR5Reach-v0", MLPSpec(13, 5, (8,)), True)])
def test_tasks_run_together_give_each_tasks_own_results(env_id, spec, expert):
    """run_tasks: a population chunk and a few extra members on more episodes, in one lock-step loop,
    give what each task gives alone, bit for bit (returns, lengths, observation sums, recorded steps)."""
    import dataclasses

    from shaped_es.rollout import probe_dims, run_tasks

    if spec is None:
        obs, act = probe_dims(env_id, {})[:2]
        spec = MLPSpec(obs, act, (8,))
    rng = np.random.default_rng(0)
    P = (rng.standard_normal((5, spec.num_params)) * 0.5).astype(np.float32)
    pop = RolloutTask(env_id, {}, spec, P[:3], np.arange(3), rng.integers(0, 2**31, (3, 2)), generation=1,
                      record=np.array([True, False, True]), max_steps=40, expert=expert, obs_stats=True)
    extra = RolloutTask(env_id, {}, spec, P[3:], np.arange(3, 5), rng.integers(0, 2**31, (2, 3)), generation=1,
                        record=True, max_steps=40, expert=expert)
    together = run_tasks([pop, extra])
    for alone, got in zip([run_task(pop), run_task(extra)], together):
        np.testing.assert_array_equal(got.members, alone.members)
        np.testing.assert_array_equal(got.returns, alone.returns)
        np.testing.assert_array_equal(got.lengths, alone.lengths)
        assert (got.obs_stats is None) == (alone.obs_stats is None)
        for a, b in zip(got.obs_stats or (), alone.obs_stats or ()):
            np.testing.assert_array_equal(a, b)
        assert [t.member for t in got.transitions] == [t.member for t in alone.transitions]
        for a, b in zip(got.transitions, alone.transitions):
            for f in dataclasses.fields(a):
                x, y = getattr(a, f.name), getattr(b, f.name)
                if isinstance(x, np.ndarray):
                    np.testing.assert_array_equal(x, y, err_msg=f.name)
                else:
                    assert x == y, f.name
    assert together[0].transitions[0].expert is not None if expert else together[0].transitions[0].expert is None


class _OffsetPoint:
    """A 2-D point (velocity control) whose info positions sit at a fixed offset (UTM-like coordinates)."""

    def __new__(cls, offset=(0.0, 0.0)):
        import gymnasium as gym

        class Env(gym.Env):
            observation_space = gym.spaces.Box(-10.0, 10.0, (4,), np.float32)
            action_space = gym.spaces.Box(-1.0, 1.0, (2,), np.float32)

            def _out(self):
                off = np.asarray(offset, np.float64)
                info = {"position": self.pos + off, "waypoint": self.goal + off}
                return np.concatenate([self.pos, self.goal - self.pos]).astype(np.float32), info

            def reset(self, *, seed=None, options=None):
                super().reset(seed=seed)
                self.pos, self.goal = np.zeros(2), self.np_random.uniform(-1.0, 1.0, 2)
                return self._out()

            def step(self, action):
                self.pos = self.pos + 0.01 * np.clip(np.asarray(action, np.float64), -1, 1)  # 1 cm steps
                obs, info = self._out()
                return obs, -float(np.linalg.norm(self.goal - self.pos)), False, False, info

        return Env()


def test_far_positions_are_recorded_from_the_episodes_first_position():
    """Positions at UTM-like offsets (4e6 m: float32 spacing 0.25 m) are recorded from each episode's first
    position, so the recorded 1 cm steps and waypoint offsets are the ones the same body records at the origin
    (before: rounded away, and M_phi's labels with them); near the origin nothing is shifted (gym_loop.FAR)."""
    import gymnasium as gym

    gym.register("OffsetPointNear-v0", entry_point=_OffsetPoint, max_episode_steps=20)
    gym.register("OffsetPointFar-v0", entry_point=_OffsetPoint, kwargs={"offset": (5e5, 4e6)}, max_episode_steps=20)
    spec = MLPSpec(4, 2, (4,))
    params = spec.init(0)[None]  # (1, n)
    got = {}
    for name in ("OffsetPointNear-v0", "OffsetPointFar-v0"):
        res = run_task(RolloutTask(name, {}, spec, params, np.arange(1), np.array([[3, 4]]), record=True))
        tr = res.transitions[0]
        got[name] = (np.diff(tr.position, axis=0), tr.waypoint - tr.position, tr.position)
    near, far = got["OffsetPointNear-v0"], got["OffsetPointFar-v0"]
    np.testing.assert_allclose(far[0], near[0], atol=1e-6)  # steps (episode boundary row included: both restart)
    np.testing.assert_allclose(far[1], near[1], atol=1e-6)
    assert np.abs(near[0]).max() > 1e-3 and np.abs(far[2]).max() < 2.0  # real steps; far ones recorded near 0


def _kart_wrapped(**kwargs):
    """Kart-v0 as a user wraps it: the world pose dropped from the observation, the reward doubled."""
    import gymnasium as gym

    env = gym.make("Kart-v0", **kwargs)
    env = gym.wrappers.TransformObservation(env, lambda o: o[4:], gym.spaces.Box(-np.inf, np.inf, (4,), np.float32))
    return gym.wrappers.TransformReward(env, lambda r: 2.0 * r)


def test_a_built_in_env_under_a_users_wrapper_runs_through_the_wrapper():
    """The batched core steps the unwrapped env: under a wrapper the episodes run through Gymnasium, so the
    policy sees the wrapper's observation (4 wide; the core's 8 failed the policy's product) and the wrapper's
    reward counts (it was silently the core's)."""
    import gymnasium as gym

    from shaped_es.envs.core import get_batch_core

    gym.register("KartWrapped-v0", entry_point=_kart_wrapped)
    assert get_batch_core(gym.make("Kart-v0")) is not None and get_batch_core(gym.make("KartWrapped-v0")) is None
    assert get_batch_core(gym.make("Kart-v0", max_episode_steps=30)) is None  # a shorter limit than the core's
    spec = MLPSpec(4, 2, (8,))
    res = run_task(RolloutTask("KartWrapped-v0", {}, spec, spec.init(0)[None], np.arange(1), np.array([[5]]),
                               record=True))
    assert res.transitions[0].state.shape[1] == 4
    env = gym.make("Kart-v0")
    obs, _ = env.reset(seed=5)
    total = 0.0
    for _ in range(int(res.lengths[0, 0])):  # the same policy on the unwrapped env: half the wrapped return
        obs, r, term, trunc, _ = env.step(forward(spec, spec.init(0)[None], obs[None, None, 4:], rowwise=True)[0, 0])
        total += r
    assert res.returns[0, 0] == pytest.approx(2.0 * total, rel=1e-4)
