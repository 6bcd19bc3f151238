"""The label sources (shaping/labels.py): what each keeps per row and the labels it gives."""

import numpy as np
import pytest

from shaped_es.data import Transitions
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import ControllerLabels, MphiLabels, ReferenceLabels
from shaped_es.shaping.mphi_inputs import clip_norm
from shaped_es.shaping.mphi_inputs import query_displacement
from shaped_es.shaping.settings import InverseDynamicsConfig


def _tr(expert=True):
    T = 6
    rng = np.random.default_rng(0)
    pos = np.cumsum(rng.normal(size=(T, 2)), axis=0).astype(np.float32)
    return Transitions(0, 0, np.zeros(T, np.int32), np.arange(T, dtype=np.int32),
                       rng.normal(size=(T, 3)).astype(np.float32), pos, pos + 1.5,
                       rng.uniform(-1, 1, (T, 2)).astype(np.float32), np.zeros(T, np.float32),
                       rng.uniform(-1, 1, (T, 2)).astype(np.float32) if expert else None)


def test_controller_labels_are_the_recorded_actions():
    tr = _tr()
    src = ControllerLabels()
    assert src.records_expert and src.ready
    np.testing.assert_array_equal(src(tr.state, src.inputs(tr)), tr.expert)
    with pytest.raises(ValueError, match="controller"):
        src.inputs(_tr(expert=False))


def test_reference_labels_are_the_policys_actions_and_keep_nothing():
    tr = _tr()
    src = ReferenceLabels(lambda s: np.tanh(s[..., :2]))
    assert src.inputs(tr).shape == (len(tr), 0)
    np.testing.assert_allclose(src(tr.state, src.inputs(tr)), np.tanh(tr.state[:, :2]))


def test_mphi_labels_ask_the_model_with_clipped_queries():
    tr = _tr()
    mphi = InverseDynamics(3, 2, 2, InverseDynamicsConfig(steps_per_generation=5, filter="none"))
    src = MphiLabels(mphi, "world")
    assert not src.ready
    mphi.add([tr])
    mphi.train()
    assert src.ready
    q = src.inputs(tr)
    np.testing.assert_array_equal(q, query_displacement(tr, "world"))
    np.testing.assert_array_equal(src(tr.state, q), mphi.label(tr.state, q))
    src.max_displacement = 0.5
    np.testing.assert_array_equal(src(tr.state, q), mphi.label(tr.state, clip_norm(q, 0.5)))
    assert np.linalg.norm(clip_norm(q, 0.5), axis=1).max() <= 0.5 + 1e-6
