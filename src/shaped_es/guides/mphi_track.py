"""One M_phi as the shaped guide keeps it: the model, its label source and its data set's parts on disk.

The run's own model (``RUN/mphi_data``) and the rival frame's (``guides/rival.py``, ``RUN/mphi_data_rival``)
are two of these: each takes in a generation's recorded steps, writes the rows it kept as one part
(``mphi_parts.py``), and checkpoints its network, optimizer and RNG with the list of parts that rebuild its
data set, so a resumed run continues exactly.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from shaped_es.data import Transitions
from shaped_es.guides.mphi_parts import DataParts
from shaped_es.shaping.inverse_dynamics import InverseDynamics
from shaped_es.shaping.labels import MphiLabels


class MphiTrack:
    """``mphi`` with its ``labels`` and the part files under ``parts_root``."""

    def __init__(self, mphi: InverseDynamics, labels: MphiLabels, parts_root: Path):
        self.mphi, self.labels, self.parts = mphi, labels, DataParts(Path(parts_root))

    @property
    def ready(self) -> bool:
        return self.labels.ready

    def add(self, generation: int, data: list[Transitions], writer):
        """Take in generation ``generation - 1``'s steps ``data`` (one Transitions) and submit the kept
        rows' part write to ``writer``; returns ``(stats, x, y, future)``: ``mphi.add``'s stats and the
        kept rows ``(rows, obs + d)``, ``(rows, act)`` (None and no future when none were kept)."""
        stats = self.mphi.add(data)
        rows = int(stats["added"])
        if not rows:
            return stats, None, None, None
        x, y = self.mphi.newest(rows)  # (rows, obs + d), (rows, act): g-1's kept training pairs
        self.parts.add(generation, rows)
        return stats, x, y, writer.submit(self.parts.write, generation, x, y)

    def save(self, state: dict[str, np.ndarray], prefix: str, parts_key: str) -> None:
        """Into ``state``: the model's training state under ``prefix`` and the parts that rebuild its
        data set under ``parts_key`` (only those its data set still holds)."""
        self.parts.trim(self.mphi.dataset_size)
        state |= {f"{prefix}{k}": v for k, v in self.mphi.state_dict(with_training=True, with_data=False).items()}
        state[parts_key] = np.array(self.parts.kept, np.int64).reshape(-1, 2)  # (k, 2) generation, rows

    def restore(self, state: dict[str, np.ndarray], prefix: str, parts_key: str, optional: bool = False) -> None:
        """What :meth:`save` wrote (the data set read back from its parts; a checkpoint holding the data
        set itself is read as it is). ``optional``: a checkpoint without this model (from a run without
        it) leaves it as it is; otherwise the model's own loading says what is missing."""
        model = {k[len(prefix):]: v for k, v in state.items() if k.startswith(prefix) and k != parts_key}
        if optional and "meta/dims" not in model:
            return
        self.mphi.load_state_dict(model)
        if "data/x" not in model and "data/size" in model:
            parts = np.asarray(state[parts_key], np.int64).reshape(-1, 2)
            self.mphi.set_data(*self.parts.read(parts, int(model["data/size"][0]), self.mphi.in_dim,
                                                self.mphi.act_dim))
