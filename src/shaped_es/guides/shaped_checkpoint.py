"""What the shaped guide's checkpoint holds, and how a resumed run takes it back: the mechanism's and the
label budget's state, the generations slept through, a wrap period found after the start, and each M_phi's
(the run's own and the rivals') network with the list of data parts that rebuild its data set (the data set
itself lives in ``RUN/mphi_data``, saved once per generation: ``mphi_parts.py``, ``mphi_track.py``). A
checkpoint names only shards and data parts that are durable: the writer thread is joined first.

``GuideCheckpoint`` is a part of ``guides/shaped.py``'s ``ShapedGuide`` (its base class), which owns the state
these methods use: ``mechanism``, ``budget``, ``_silent``, ``position_period`` and ``_wrap_warned``, ``track``,
``rivals`` and ``_tracks``, ``step_norm``, ``labels``, ``_last_generation``, ``_saved`` (read by the pruning
after the checkpoint, ``shaped_background.py``), ``_noise_said`` and ``_cache``.
"""

from __future__ import annotations

import numpy as np

from shaped_es.guides.mphi_parts import DamagedPart
from shaped_es.guides.probe_file import FILE as PROBE_FILE
from shaped_es.guides.rival import owned


class GuideCheckpoint:
    """The checkpoint hooks of a :class:`~shaped_es.guides.shaped.ShapedGuide` (the module docstring names the
    guide's attributes these methods use)."""

    def state_dict(self) -> dict[str, np.ndarray]:
        self._join_writes()  # the checkpoint may only name shards and data parts that are durable
        st = {f"mechanism/{k}": v for k, v in self.mechanism.state_dict().items()}
        st |= {f"budget/{k}": v for k, v in self.budget.state_dict().items()}
        st["silent"] = np.array(sorted(self._silent), np.int64)
        if self.position_period is not None:  # found after the start: the resumed rollouts take it too
            st["late_period"] = np.asarray(self.position_period, np.float64)
        if self.track is not None:
            self.track.save(st, "mphi/", "mphi_parts")
            st["step_norm"] = self.step_norm
        for r in owned(self.rivals):  # a rival on another's track (rival.SHOOT_HOLD) has nothing of its own
            r.track.save(st, r.prefix, r.parts_key)
        nxt = self._last_generation + 1
        self._saved = (self._last_generation, [t.parts.oldest(default=nxt) for t in self._tracks])
        return st

    def load_state_dict(self, state: dict[str, np.ndarray]) -> None:
        self.mechanism.load_state_dict({k[10:]: v for k, v in state.items() if k.startswith("mechanism/")})
        self.budget.load_state_dict({k[7:]: v for k, v in state.items() if k.startswith("budget/")})
        self._silent = {int(g) for g in np.asarray(state.get("silent", np.zeros(0)), np.int64).reshape(-1)}
        if "late_period" in state:
            self.position_period = np.asarray(state["late_period"], np.float64).reshape(-1)  # (d,)
            self._wrap_warned = True
        self._noise_said = None  # decided at the first generation after the checkpoint (after_tell)
        self._cache.clear()
        if self.track is None:
            return
        self.track.restore(state, "mphi/", "mphi_parts")  # the data set lives in RUN/mphi_data
        self.step_norm = np.asarray(state["step_norm"], dtype=np.float64)
        for r in owned(self.rivals):  # a checkpoint from before a rival: it starts afresh
            try:
                r.track.restore(state, r.prefix, r.parts_key, optional=True)
            except DamagedPart as exc:  # a damaged file: the checkpoint's message says what to do
                raise ValueError(f"the {r.name} rival's model: {exc}") from None
            except ValueError as exc:  # its shape comes from the config and the probe's choices, not the checkpoint
                raise ValueError(f"the {r.name} rival's model: {exc} (the run that wrote it had another setup: "
                                 f"its config or RUN/{PROBE_FILE}, which holds the shooting labels' horizon)") from None
        self.labels.max_displacement = self.labels_max_displacement()
