"""The env's threshold during a run: one line when the test reward first reaches it, and where the final
JSON says when (``shaped-es train`` / ``resume``; ``benchmark`` and ``report`` count it in their tables).

The threshold is the one ``benchmark`` uses (``envs.thresholds.env_threshold``: the env's registered
``reward_threshold``, a user's env's included); the command line passes it in, so this layer does not read
the benchmark's. A resumed run that had already reached it says nothing again.
"""

from __future__ import annotations

import sys

from shaped_es.monitor.callbacks import Callback


def _num(v) -> float | None:
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


class ThresholdNotice(Callback):
    """Prints ``shaped-es: RUN: test reward 8.12 reached the threshold 8.0 (SOURCE) at generation 14``
    once; :attr:`first` is the generation (1-based, as the progress line counts) or None."""

    def __init__(self, value: float, source: str, stream=None):
        self.value, self.source, self.stream = float(value), source, stream
        self.first: int | None = None

    def on_start(self, run) -> None:
        super().on_start(run)
        for row in run.store.read_metrics():  # a resumed run: reached before?
            self._check(row, say=False)

    def on_generation(self, row: dict) -> bool | None:
        self._check(row, say=True)
        return True

    def _check(self, row: dict, say: bool) -> None:
        test, gen = _num(row.get("test_reward_mean")), _num(row.get("generation"))
        if self.first is not None or test is None or gen is None or test < self.value:
            return
        self.first = int(gen) + 1
        if say:
            name = self.run.store.root.name if self.run is not None else "run"
            where = self.source.split(" (")[0]  # "PointVel-v0 reward_threshold": its reason is in the JSON
            print(f"shaped-es: {name}: test reward {test:.2f} reached the threshold {self.value:g} ({where}) "
                  f"at generation {self.first}", file=self.stream or sys.stderr, flush=True)
