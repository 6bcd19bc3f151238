"""Batched behaviour cloning: lowers the loss, no-op at 0 steps, batched == one member at a time."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from shaped_es.policies import MLPSpec, forward
from shaped_es.shaping.cloning import CloningConfig, clone_population, clone_sampled, pad_population
from shaped_es.shaping.member_rows import MemberRows
from shaped_es.shaping.shared_rows import SharedRows

SPEC = MLPSpec(obs_dim=5, act_dim=2, hidden=(8, 8))


def _population(P=4, lens=(60, 45, 80, 30), seed=0):
    """Members near a teacher policy, each with its own states and the teacher's actions as labels."""
    rng = np.random.default_rng(seed)
    teacher = SPEC.init(100) * 5  # (n,) a policy with non-trivial actions
    theta = np.stack([SPEC.init(i) for i in range(P)])  # (P, n)
    states = [rng.normal(size=(n, SPEC.obs_dim)).astype(np.float32) for n in lens[:P]]
    labels = [forward(SPEC, teacher[None], s[None])[0] for s in states]  # (T_i, act) each
    return theta, states, labels


@pytest.mark.parametrize("optimizer", ["adam", "sgd"])
def test_cloning_lowers_loss_for_every_member(optimizer):
    theta, states, labels = _population()
    lr = 1e-2 if optimizer == "adam" else 0.5
    cfg = CloningConfig(steps=60, lr=lr, optimizer=optimizer)
    res = clone_population(SPEC, theta, states, labels, config=cfg)
    assert res.theta_star.shape == theta.shape and res.theta_star.dtype == np.float32
    assert np.all(res.loss_after < 0.7 * res.loss_before)
    np.testing.assert_array_equal(res.samples, [60, 45, 80, 30])
    for i in range(4):  # loss_before is the plain MSE of the member's policy on its data
        mse = np.mean((forward(SPEC, theta[i : i + 1], states[i][None])[0] - labels[i]) ** 2)
        assert res.loss_before[i] == pytest.approx(mse, rel=1e-5)


def test_zero_steps_leaves_theta_unchanged():
    theta, states, labels = _population()
    res = clone_population(SPEC, theta, states, labels, config=CloningConfig(steps=0))
    np.testing.assert_array_equal(res.theta_star, theta)
    np.testing.assert_array_equal(res.loss_before, res.loss_after)


@pytest.mark.parametrize("optimizer,batch", [("adam", 16), ("sgd", 16), ("adam", 0)])
def test_batched_equals_one_member_at_a_time(optimizer, batch):
    theta, states, labels = _population()
    cfg = CloningConfig(steps=25, lr=1e-2, batch_size=batch, optimizer=optimizer)
    seeds = [11, 12, 13, 14]
    res = clone_population(SPEC, theta, states, labels, config=cfg, seeds=seeds)
    for i in range(4):
        alone = clone_population(SPEC, theta[i : i + 1], [states[i]], [labels[i]], config=cfg,
                                 seeds=[seeds[i]])
        np.testing.assert_allclose(res.theta_star[i], alone.theta_star[0], atol=1e-5, rtol=0)
        assert not np.array_equal(alone.theta_star[0], theta[i])


def test_default_seeds_are_deterministic_and_per_member():
    theta, states, labels = _population()
    cfg = CloningConfig(steps=10, lr=1e-2, batch_size=8, seed=7)
    a = clone_population(SPEC, theta, states, labels, config=cfg)
    b = clone_population(SPEC, theta, states, labels, config=cfg)
    cfg8 = CloningConfig(steps=10, lr=1e-2, batch_size=8, seed=8)
    c = clone_population(SPEC, theta, states, labels, config=cfg8)
    np.testing.assert_array_equal(a.theta_star, b.theta_star)
    assert not np.array_equal(a.theta_star, c.theta_star)


def test_padded_input_with_mask_equals_list_input_and_max_samples_uses_newest():
    theta, states, labels = _population()
    cfg = CloningConfig(steps=15, lr=1e-2, batch_size=16, max_samples=40)
    S, A, M = pad_population(states, labels)
    assert S.shape == (4, 80, 5) and A.shape == (4, 80, 2) and M.sum() == 215
    from_list = clone_population(SPEC, theta, states, labels, config=cfg, seeds=[1, 2, 3, 4])
    S[~M] = np.nan  # whatever the padding holds is ignored
    from_pad = clone_population(SPEC, theta, S, A, M, config=cfg, seeds=[1, 2, 3, 4])
    np.testing.assert_array_equal(from_list.samples, [40, 40, 40, 30])
    np.testing.assert_allclose(from_pad.theta_star, from_list.theta_star, atol=1e-6)
    newest = clone_population(SPEC, theta, [s[-40:] for s in states], [a[-40:] for a in labels],
                              config=CloningConfig(steps=15, lr=1e-2, batch_size=16, max_samples=0),
                              seeds=[1, 2, 3, 4])
    np.testing.assert_allclose(newest.theta_star, from_list.theta_star, atol=1e-6)


def test_member_without_data_is_left_alone():
    theta, states, labels = _population()
    states[2], labels[2] = states[2][:0], labels[2][:0]
    res = clone_population(SPEC, theta, states, labels, config=CloningConfig(steps=10, lr=1e-2))
    np.testing.assert_array_equal(res.theta_star[2], theta[2])
    assert np.isnan(res.loss_before[2]) and np.isnan(res.loss_after[2])
    assert np.all(res.loss_after[[0, 1, 3]] < res.loss_before[[0, 1, 3]])


def test_rejects_bad_shapes():
    theta, states, labels = _population()
    with pytest.raises(ValueError, match="parameters"):
        clone_population(SPEC, theta[:, :-1], states, labels)
    with pytest.raises(ValueError, match="members"):
        clone_population(SPEC, theta[:3], states, labels)
    with pytest.raises(ValueError, match="seeds"):
        clone_population(SPEC, theta, states, labels, seeds=[1, 2])


def test_config_validation():
    with pytest.raises(ValueError, match="optimizer"):
        CloningConfig(optimizer="rmsprop")
    with pytest.raises(ValueError):
        CloningConfig(lr=0.0)


def test_clone_sampled_equals_cloning_fully_labelled_data():
    """Labelling only the drawn rows gives the theta* of labelling all of D_i (same draws, same steps)."""
    theta, states, _ = _population()
    rng = np.random.default_rng(7)
    queries = [rng.normal(size=(len(s), 2)).astype(np.float32) for s in states]
    teacher = MLPSpec(obs_dim=7, act_dim=2, hidden=(6,))
    t_theta = teacher.init(3)[None] * 4

    def label_fn(s, q):
        x = np.concatenate([s, q], axis=-1)
        lead = x.shape[:-1]
        return forward(teacher, t_theta, x.reshape(1, -1, 7))[0].reshape(*lead, 2)

    cfg = CloningConfig(steps=15, lr=1e-2, batch_size=16, max_samples=50)
    seeds = np.array([11, 12, 13, 14])
    full = clone_population(SPEC, theta, states, [label_fn(s, q) for s, q in zip(states, queries)],
                            config=cfg, seeds=seeds)
    fast = clone_sampled(SPEC, theta, MemberRows.from_lists(states, queries), label_fn, cfg, seeds)
    np.testing.assert_allclose(fast.theta_star, full.theta_star, rtol=1e-5, atol=1e-6)
    assert np.all(fast.loss_after < fast.loss_before)
    np.testing.assert_array_equal(fast.samples, [50, 45, 50, 30])
    assert fast.label_std > 0.05
    one = clone_sampled(SPEC, theta[2:3], MemberRows.from_lists(states[2:3], queries[2:3]), label_fn, cfg,
                        seeds[2:3])
    np.testing.assert_allclose(one.theta_star[0], fast.theta_star[2], rtol=1e-5, atol=1e-6)


def test_a_costly_label_source_labels_each_drawn_row_once_with_the_same_result():
    """``label_once``: the distinct drawn rows of each member are labelled, then scattered to every draw."""
    theta, states, _ = _population()
    queries = [np.random.default_rng(1).normal(size=(len(s), 2)).astype(np.float32) for s in states]
    calls = []

    class Costly:
        label_once = True

        def __call__(self, s, q):
            calls.append(int(np.prod(s.shape[:-1])))
            return np.tanh(s[..., :2] + q).astype(np.float32)

    cheap = lambda s, q: np.tanh(s[..., :2] + q).astype(np.float32)  # noqa: E731 - the same labels
    cfg = CloningConfig(steps=40, lr=1e-2, batch_size=16, max_samples=50)
    seeds = np.array([11, 12, 13, 14])
    rows = MemberRows.from_lists(states, queries)
    a = clone_sampled(SPEC, theta, rows, Costly(), cfg, seeds)
    b = clone_sampled(SPEC, theta, rows, cheap, cfg, seeds)
    np.testing.assert_array_equal(a.theta_star, b.theta_star)
    assert calls == [sum(min(len(s), 50) for s in states)]  # 40 x 16 draws per member cover every row once


def test_clone_sampled_member_without_data_is_unchanged():
    theta, states, _ = _population()
    states[1] = states[1][:0]
    queries = [np.zeros((len(s), 2), np.float32) for s in states]
    res = clone_sampled(SPEC, theta, MemberRows.from_lists(states, queries), lambda s, q: np.full(s.shape[:-1] + (2,), 0.5, np.float32),
                        CloningConfig(steps=5, lr=1e-2), np.arange(4))
    np.testing.assert_array_equal(res.theta_star[1], theta[1].astype(np.float32))
    assert np.isnan(res.loss_before[1]) and not np.isnan(res.loss_before[0])
    assert not np.array_equal(res.theta_star[0], theta[0].astype(np.float32))


def test_reference_metrics_know_a_perfect_and_a_useless_labeller():
    theta, states, _ = _population()
    queries = [np.zeros((len(s), 2), np.float32) for s in states]
    teacher = SPEC.init(100) * 5

    def ref(s):
        lead = s.shape[:-1]
        return forward(SPEC, teacher[None], s.reshape(1, -1, SPEC.obs_dim))[0].reshape(*lead, 2)

    cfg = CloningConfig(steps=30, lr=1e-2, batch_size=32)
    data = MemberRows.from_lists(states, queries)
    good = clone_sampled(SPEC, theta, data, lambda s, q: ref(s), cfg, np.arange(4), reference_fn=ref)
    assert good.reference["label_ref_error"] == pytest.approx(0.0, abs=1e-6)  # the paper's Fig. 5 loss
    assert good.reference["label_beats_own"] > 0.95
    assert good.reference["clone_ref_error"] < good.reference["own_ref_error"]
    bad = clone_sampled(SPEC, theta, data, lambda s, q: -ref(s), cfg, np.arange(4), reference_fn=ref)
    assert bad.reference["label_ref_error"] > bad.reference["own_ref_error"]
    assert bad.reference["clone_ref_error"] > bad.reference["own_ref_error"]


def test_member_rows_in_blocks_equal_the_concatenated_lists():
    """D_i spread over per-generation blocks gives the rows (and theta*) of its concatenation."""
    rng = np.random.default_rng(4)
    P, gens = 3, 3
    blocks = [[rng.normal(size=(int(rng.integers(0, 9)), 5)).astype(np.float32) for _ in range(P)]
              for _ in range(gens)]  # blocks[g][i]: member i's rows of generation g
    qs = [[rng.normal(size=(len(x), 2)).astype(np.float32) for x in blk] for blk in blocks]
    spans, S, Q = np.zeros((P, gens, 2), np.int64), [], []
    for g in range(gens):
        lens = np.array([len(x) for x in blocks[g]])
        spans[:, g, 1] = np.cumsum(lens)
        spans[:, g, 0] = spans[:, g, 1] - lens
        S.append(np.concatenate(blocks[g]))
        Q.append(np.concatenate(qs[g]))
    data = MemberRows(S, Q, spans)
    flat = MemberRows.from_lists([np.concatenate([blocks[g][i] for g in range(gens)]) for i in range(P)],
                                 [np.concatenate([qs[g][i] for g in range(gens)]) for i in range(P)])
    np.testing.assert_array_equal(data.lengths(), flat.lengths())
    for keep in (0, 4, 7):
        a, b = data.newest(keep), flat.newest(keep)
        np.testing.assert_array_equal(a.lengths(), b.lengths())
        pos = np.stack([rng.integers(0, max(n, 1), size=(6, 4)) for n in a.lengths()], axis=1)  # (6, P, 4)
        pos[:, a.lengths() == 0] = 0
        sa, qa = a.gather(pos)
        sb, qb = b.gather(pos)
        np.testing.assert_array_equal(sa, sb)
        np.testing.assert_array_equal(qa, qb)


@pytest.mark.parametrize("through_shared_memory", [False, True])
def test_fitting_in_chunks_elsewhere_gives_the_same_theta_star(through_shared_memory):
    theta, states, labels = _population()
    queries = [np.zeros((len(s), 2), np.float32) for s in states]
    data = MemberRows.from_lists(states, queries)
    cfg = CloningConfig(steps=12, lr=1e-2, batch_size=16)
    label = lambda s, q: np.tanh(s[..., :2])  # noqa: E731
    calls = []

    def fake_map(fn, tasks):
        calls.append(len(tasks))
        tasks = [pickle.loads(pickle.dumps(t)) for t in tasks]  # as a worker receives them
        assert all((t.S is None) == through_shared_memory for t in tasks)
        return [fn(t) for t in tasks]

    shared = SharedRows() if through_shared_memory else None
    one = clone_sampled(SPEC, theta, data, label, cfg, np.arange(4))
    many = clone_sampled(SPEC, theta, data, label, cfg, np.arange(4), map_fit=fake_map, map_chunks=3,
                         shared=shared)
    if shared is not None:
        shared.close()
    assert calls == [3]
    np.testing.assert_allclose(many.theta_star, one.theta_star, rtol=1e-6, atol=1e-7)
    np.testing.assert_allclose(many.loss_after, one.loss_after, rtol=1e-6)


def test_subsample_draws_rows_without_replacement_in_order():
    states = [np.arange(40, dtype=np.float32).reshape(20, 2), np.arange(40, 70, dtype=np.float32).reshape(15, 2)]
    queries = [s[:, :1] * 10 for s in states]
    one = MemberRows(states, queries, np.array([[[0, 20], [5, 15]]], np.int64))  # one member over two blocks
    sub = one.subsample(12, np.random.default_rng(0))
    S, Q = sub.states[0], sub.queries[0]
    assert sub.lengths().tolist() == [12] and len(np.unique(S[:, 0])) == 12
    every = np.concatenate([states[0], states[1][5:15]])  # the member's 30 rows, oldest first
    rows = [int(np.flatnonzero((every == r).all(1))[0]) for r in S]
    assert rows == sorted(rows) and np.array_equal(Q, S[:, :1] * 10)  # each row keeps its own query
    assert one.subsample(30, np.random.default_rng(0)) is one  # no more rows than asked: itself
    with pytest.raises(ValueError, match="one member"):
        MemberRows.from_lists(states, queries).subsample(5, np.random.default_rng(0))
