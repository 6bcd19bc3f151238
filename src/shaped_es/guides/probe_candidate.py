"""The label probe's best simulated candidate, judged beside generation 0 (``shaping.mean_clone.probe_candidate``).

Before the first generation the label probe (``label_probe.py``) clones the initial mean toward each frame
variant's labels and each shooting horizon's (3 DAgger rounds, ``clone_probe.py``) and drives every clone on
10 episodes. Those clones are policies a run would otherwise make again only at generation 2 or 3, once
its own M_phi has data. On the suite's committed runs (``docs/benchmarks/test_policy_v11``, seeds 0-9) the
best of them already scored at or near the success threshold on the points (PointVel-v0 9.1-9.4 against its
8.5, on every seed), the unicycle, the rover and the kart, while the population around the initial mean
scored 2-7; those runs reached the threshold at generations 4-10.

So a shaped run offers the probe's best clone (by its mean return on the probe's episodes) as generation 0's
candidate, judged by the run's acceptance rule beside the mean like every later one (``mechanisms/
candidate.py``), and it must also beat every member of generation 0's population on their common episodes: a
jump from the initial mean to a policy worse than what the search already sampled around it is no shortcut.
Judged by the acceptance rule alone (``docs/benchmarks/probe_candidate_v14``), it won on 4 of the swimmer's 10
seeds, whose population's best members swim at 17-26 where the clone scores 5 at most, and 3 of those runs
reached the threshold 4-7 generations later than without it; none of those 4 beat the best member. A win
makes it the mean, as any accepted candidate. A loss is not held against the labels
(the label budget does not count it): the run goes on exactly as without it, one candidate's and the mean's
episodes dearer. The clone is kept in ``RUN/label_probe_candidate.npy`` beside ``label_probe.json``, so a run
restarted before its first checkpoint judges the same one; a probe file without it (a run from before) has
none, as that run had none. Read with ``allow_pickle=False``.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from shaped_es.config import ConfigError
from shaped_es.rundir.atomic import StoreError, atomic_write_bytes, read_regular

FILE = "label_probe_candidate.npy"


def rank(returns: dict[str, list[float]], thetas: dict[str, np.ndarray]) -> list[str]:
    """The simulated candidates' names (those with parameters and returns), highest mean return first (the first
    in ``returns``' order on a tie)."""
    names = [k for k in returns if k in thetas and len(returns[k])]
    return sorted(names, key=lambda k: (-float(np.mean(returns[k])), names.index(k)))


def best(returns: dict[str, list[float]], thetas: dict[str, np.ndarray]) -> tuple[str, np.ndarray] | None:
    """``(name, theta (n,))`` of the simulated candidate with the highest mean return (:func:`rank`'s first);
    None when there is none."""
    names = rank(returns, thetas)
    return (names[0], np.asarray(thetas[names[0]], np.float32)) if names else None


def save(path: Path, theta: np.ndarray) -> None:
    buf = io.BytesIO()
    np.save(buf, np.asarray(theta, np.float32), allow_pickle=False)
    atomic_write_bytes(path, buf.getvalue())


def load(path: Path, num_params: int) -> np.ndarray | None:
    """The saved clone ``(num_params,)`` float32, or None if there is no file; one ``ConfigError`` line if the
    file is not one this version wrote for this policy."""
    if not (path.exists() or path.is_symlink()):
        return None
    try:
        theta = np.load(io.BytesIO(read_regular(path)), allow_pickle=False)
    except (ValueError, OSError, EOFError, StoreError) as exc:  # EOFError: an empty file
        raise ConfigError(f"{path} is not a probe candidate this version wrote ({exc}); move it away (the run "
                          f"then judges no candidate at generation 1)") from None
    if theta.shape != (num_params,) or not np.isfinite(theta).all():
        raise ConfigError(f"{path} holds {theta.shape} parameters, expected ({num_params},) and finite: not this "
                          f"run's policy; move it away (the run then judges no candidate at generation 1)")
    return theta.astype(np.float32)
