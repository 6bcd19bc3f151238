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

import numpy as np

from shaped_es import seeding
from shaped_es.data import Transitions
from shaped_es.guides.mphi_parts import DataParts
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


class RivalLabels:
    """The second model, its labels and its saved data parts."""

    def __init__(self, obs_dim: int, pos_dim: int, act_dim: int, mphi_cfg, frame: str, root: Path, seed: int):
        cfg = dataclasses.replace(mphi_cfg, frame=frame, seed=seeding.derive_seed(seed, seeding.SHAPING, RIVAL_KEY))
        self.frame = frame
        self.mphi = InverseDynamics(obs_dim, pos_dim, act_dim, cfg)
        self.labels = MphiLabels(self.mphi, frame, cfg.query_scale, cfg.query_mix)
        self.parts = DataParts(Path(root) / DIR)

    @property
    def ready(self) -> bool:
        return self.labels.ready

    def add(self, generation: int, data: list[Transitions], writer) -> list:
        """Take in generation ``generation - 1``'s steps ``data`` (one Transitions); returns the futures of
        its part write (submitted to ``writer``)."""
        rows = int(self.mphi.add(data)["added"])
        if not rows:
            return []
        x, y = self.mphi.newest(rows)  # (rows, obs + d'), (rows, act)
        self.parts.add(generation, rows)
        return [writer.submit(self.parts.write, generation, x, y)]

    def train(self) -> None:
        self.mphi.train()

    def state_dict(self) -> dict[str, np.ndarray]:
        self.parts.trim(self.mphi.dataset_size)
        st = dict(self.mphi.state_dict(with_training=True, with_data=False))
        st["parts"] = np.array(self.parts.kept, np.int64).reshape(-1, 2)  # (k, 2) generation, rows
        return st

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        if "meta/dims" not in state:  # a checkpoint from a run without the rival: it starts afresh
            return
        self.mphi.load_state_dict({k: v for k, v in state.items() if k != "parts"})
        if "data/size" in state:
            parts = np.asarray(state["parts"], np.int64).reshape(-1, 2)
            self.mphi.set_data(*self.parts.read(parts, int(state["data/size"][0]), self.mphi.in_dim,
                                                self.mphi.act_dim))
