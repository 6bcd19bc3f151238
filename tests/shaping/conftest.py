"""Synthetic transitions for the shaping tests."""

from __future__ import annotations

import numpy as np
import pytest

from shaped_es.data import Transitions


def synth_transitions(
    rng: np.random.Generator,
    episodes: int = 2,
    steps: int = 30,
    obs_dim: int = 4,
    act_dim: int = 2,
    pos_dim: int = 2,
    B: np.ndarray | None = None,
    returns: list[float] | None = None,
    generation: int = 0,
    member: int = 0,
) -> Transitions:
    """Episodes whose positions move by ``B @ a_t`` each step (a known linear inverse model)."""
    B = np.eye(pos_dim, act_dim) if B is None else B
    returns = [10.0] * episodes if returns is None else returns
    ep, st, s, p, w, a, r = [], [], [], [], [], [], []
    for e in range(episodes):
        act = rng.uniform(-0.8, 0.8, size=(steps, act_dim)).astype(np.float32)  # (T, act)
        pos = np.cumsum(np.vstack([rng.normal(size=(1, pos_dim)), act[:-1] @ B.T]), axis=0)[:steps]  # (T, d)
        ep.append(np.full(steps, e, np.int32))
        st.append(np.arange(steps, dtype=np.int32))
        s.append(rng.normal(size=(steps, obs_dim)).astype(np.float32))
        p.append(pos.astype(np.float32))
        w.append((pos + act @ B.T).astype(np.float32))  # the point the action actually reaches
        a.append(act)
        r.append(np.full(steps, returns[e] / max(steps, 1), np.float32))
    cat = np.concatenate
    return Transitions(generation, member, cat(ep), cat(st), cat(s), cat(p), cat(w), cat(a), cat(r))


@pytest.fixture
def make_transitions():
    return synth_transitions

