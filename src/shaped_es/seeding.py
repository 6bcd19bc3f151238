"""Seed derivation: every generation, member and episode gets its own seed from the run's root seed.

Seeds depend only on *what* is evaluated (stream, generation, member, episode), never on which worker or
executor evaluates it, so a run is reproducible whatever ran it and a resumed run continues exactly.

By default all members of a generation share their training episode seeds (common random numbers): the
two mirror images of an antithetic pair, and every pair, face the same episodes, so differences in return
come from the parameters and not from the luck of the draw.
"""

from __future__ import annotations

import numpy as np

TRAIN, TEST, STRATEGY, SHAPING, INIT = 1, 2, 3, 4, 5
EVAL = 99  # ``evaluate`` / ``render`` episodes of a saved policy: outside every training and test stream


def derive_seed(root: int, *keys: int) -> int:
    """A 31-bit seed from ``root`` and integer ``keys`` (SeedSequence hashing; stable across versions)."""
    ss = np.random.SeedSequence([int(root) & 0xFFFFFFFF, *[int(k) & 0xFFFFFFFF for k in keys]])
    return int(ss.generate_state(1, dtype=np.uint32)[0] >> 1)


def initial_mean(spec, root: int) -> np.ndarray:
    """A run's initial search mean ``(n,)``: ``spec``'s (a ``policies.MLPSpec``) initial weights from the run's
    root seed; the trainer's, the label probe's and the generation-0 candidate's mean are this one."""
    return spec.init(derive_seed(root, INIT))


def episode_seeds(
    root: int, stream: int, generation: int, members: np.ndarray, episodes: int, common: bool = True
) -> np.ndarray:
    """Episode seeds ``(m, episodes)`` int64 for the given member indices.

    With ``common=True`` the member index is left out of the key (common random numbers).
    """
    members = np.asarray(members, dtype=np.int64)
    out = np.empty((members.shape[0], episodes), dtype=np.int64)  # (m, E)
    if common:  # one row for every member
        out[:] = [derive_seed(root, stream, generation, 0, e) for e in range(episodes)]
        return out
    for r, m in enumerate(members):
        for e in range(episodes):
            out[r, e] = derive_seed(root, stream, generation, int(m) + 1, e)
    return out


def evaluation_seeds(episodes: int = 15, seed: int = 12345) -> list[int]:
    """The episode seeds ``shaped-es evaluate --episodes E --seed S`` (and ``render``) run, in order:
    ``env.reset(seed=s)`` for each gives the episodes it reports (``evaluate``'s JSON lists them too)."""
    return [int(s) for s in episode_seeds(seed, EVAL, 0, np.zeros(1), episodes)[0]]
