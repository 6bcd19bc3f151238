"""Callbacks from Python: called after every generation's metrics row, able to stop the run (the habit of
Stable-Baselines3's ``BaseCallback``, whose ``_on_step`` returns False to stop training).

A callback is a function ``row -> bool | None`` (``row``: the ``metrics.csv`` row as a dict of numbers,
``None`` for an empty cell; return ``False`` to stop, anything else continues) or a :class:`Callback`
(``on_start(run)`` once, ``on_generation(row)`` per row, ``on_end(rows)`` at the end; ``self.run`` is the
run loop: ``run.cfg``, ``run.store``, ``run.c`` the counters, and for ES ``run.strategy``). A list of
them runs in order, each seeing every row.

A run stopped by a callback completes the rows still waiting for their test episodes, checkpoints and
returns; ``shaped-es resume`` continues it later like any other run.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any


class Callback:
    """Base class: override what you need; ``on_generation`` returning ``False`` stops the run."""

    run: Any = None  # the run loop (trainer.Trainer or baselines.ppo.PPORun), set by on_start

    def on_start(self, run) -> None:
        self.run = run

    def on_generation(self, row: dict) -> bool | None:
        return True

    def on_end(self, rows: list[dict]) -> None:
        pass

    def on_checkpoint(self, generation: int) -> None:
        """After the checkpoint of ``generation`` generations that ``video_every`` asked for."""


class FunctionCallback(Callback):
    """A plain function ``row -> bool | None`` as a :class:`Callback`."""

    def __init__(self, fn: Callable[[dict], Any]):
        self.fn = fn

    def on_generation(self, row: dict) -> bool | None:
        return self.fn(row)


def as_callbacks(callback) -> list[Callback]:
    """``None``, one callback (function or :class:`Callback`) or an iterable of them, as a list."""
    if callback is None:
        return []
    items: Iterable = callback if isinstance(callback, (list, tuple)) else [callback]
    out = []
    for cb in items:
        if isinstance(cb, Callback):
            out.append(cb)
        elif callable(cb):
            out.append(FunctionCallback(cb))
        else:
            raise TypeError(f"callback must be a function row -> bool or a shaped_es.monitor.callbacks.Callback, "
                            f"got {type(cb).__name__}")
    return out
