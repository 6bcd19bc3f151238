import numpy as np
import pytest

from shaped_es.policies import MLPSpec
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
