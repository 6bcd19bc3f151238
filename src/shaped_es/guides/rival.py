"""A rival label variant (``shaping.inverse_dynamics.rival_frame``): a second ``M_phi`` in another frame,
trained on the same recorded steps, whose labels make a second candidate each generation.

Which displacement frame makes M_phi's labels pay depends on the body, and the label probe before
generation 0 (``label_probe.py``) cannot always tell: forced by hand, the waypoint frame solves
Unicycle-v0 in 6.8 generations where the default (``both``) takes 14.9, yet it is never accepted on the
points or the car (``docs/benchmarks/frames_waypoint``), and the probe's simulated candidate chose it on
1 of 10 unicycle seeds. So instead of choosing before the run, the run keeps both: the mechanism
``candidate`` (``mechanisms/candidate.py``) clones the mean toward each model's labels and evaluates both
clones beside the population; selection (the same acceptance rule) takes whichever wins, generation by
generation. Cost: a second M_phi's training steps (in the shaping thread, beside the rollouts), a second
clone of the mean, and one more candidate's episodes.

The rival model has no query clip (the probe's clip is the primary's) and its own data parts
(``RUN/mphi_data_rival``), so a resumed run rebuilds it exactly as the primary's.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

from shaped_es import seeding
from shaped_es.guides.mphi_track import MphiTrack
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import MphiLabels

RIVAL_KEY = 1_000_021  # seed key of the rival model (its init and minibatches)
DIR = "mphi_data_rival"


def rival_frame(cfg, frame: str, pos_dim: int) -> str | None:
    """The rival's frame for this run, or None: only with M_phi's labels and the candidate mechanism, a
    waypoint space of at least 2 dimensions, and a frame other than the run's own."""
    sh = cfg.shaping
    want = sh.inverse_dynamics.rival_frame
    if want == "none" or want == frame or pos_dim < 2 or sh.labels != "mphi" or sh.mechanism != "candidate":
        return None
    return want


def rival_track(obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, frame: str, root: Path,
                seed: int) -> MphiTrack:
    """The rival model in ``frame`` (M_phi's other settings as the run's, its own seed), its labels (no
    query clip) and its data parts under ``root / DIR``."""
    cfg = dataclasses.replace(mphi_cfg, frame=frame, seed=seeding.derive_seed(seed, seeding.SHAPING, RIVAL_KEY))
    mphi = InverseDynamics(obs_dim, pos_dim, act_dim, cfg)
    return MphiTrack(mphi, MphiLabels(mphi, frame, cfg.query_scale, cfg.query_mix), Path(root) / DIR)
