"""The label probe's step_change choice (guides/probe_step_change.py): on where M_phi without it explains little
of held-out actions and with it far more, off elsewhere; the configured value as given."""

from types import SimpleNamespace

import numpy as np

from helpers import point_mass
from shaped_es.guides.probe_step_change import PLAIN_FAILS, RATIO, choose, decide
from shaped_es.shaping.settings import InverseDynamicsConfig

CFG = InverseDynamicsConfig(min_return=-1e9, seed=0)


def data(gain=None):
    return [[point_mass(10 + g, episodes=8, gain=gain)] for g in range(2)]  # two probe generations, one member each


def test_a_weakly_actuated_second_order_body_takes_it():
    on, e = choose(4, 2, 2, data(), CFG)
    assert on and e["plain"] >= PLAIN_FAILS and e["change"] <= RATIO * e["plain"], e


def test_a_strongly_actuated_one_keeps_the_plain_model():
    """A torque that sets most of each step (gain 1: the velocity is mostly this step's action): nothing to gain."""
    on, e = choose(4, 2, 2, data(gain=1.0), CFG)
    assert not on and e["plain"] < PLAIN_FAILS, e


def test_configured_values_and_what_cannot_be_scored():
    spec = SimpleNamespace(obs_dim=4, act_dim=2)
    for v in (True, False):
        assert decide(SimpleNamespace(step_change=v), spec, 2, data(), CFG) == (v, {})
    assert choose(4, 2, 2, data()[:1], CFG) == (False, {})
    on, e = decide(SimpleNamespace(step_change="auto"), spec, 2, data(), CFG)
    assert on and set(e) == {"plain", "change"}
    assert np.isfinite(list(e.values())).all()
