"""TensorBoard events of a run (``DIR/tb``): the ``metrics.csv`` row as grouped scalars vs env steps.

Every numeric column of a row becomes the scalar ``GROUP/column`` (the column name unchanged, so a tag
is found in ``metrics.csv`` under the same name) at global step ``row["env_steps"]`` (cumulative
training env steps, the x axis the results are stated in; ``misc/generation`` maps it back):

- ``train/``: ``train_*`` (population rewards);
- ``test/``: ``test_*`` (the best member's test episodes);
- ``time/``: ``*_time_s`` and ``time_*`` (wall and CPU time, per-phase seconds);
- ``shaping/``: ``mphi_*``, ``clone_*``, ``label_*``, ``surrogate_*``, ``shaping_*``, ``*_ref_error``
  (the ``shaped`` method's inverse-dynamics model, cloning, labels and surrogates);
- ``misc/``: everything else (``generation``, ``update_norm``, ``gen_env_steps``, ...).

A time column of the shaping phases (``clone_cpu_time_s``) is a time: ``time/`` is matched first.
None and non-finite values are skipped (``metrics.csv`` keeps them).
"""

from __future__ import annotations

import math
import numbers
import time
from pathlib import Path

GROUPS = ("train", "test", "shaping", "time", "misc")
_SHAPING_PREFIXES = ("mphi_", "clone_", "label_", "surrogate_", "shaping_")


def tb_tag(column: str) -> str:
    """The TensorBoard tag of a ``metrics.csv`` column: ``GROUP/column`` (module doc)."""
    if column.endswith("_time_s") or column.startswith("time_"):
        group = "time"
    elif column.startswith("train_"):
        group = "train"
    elif column.startswith("test_"):
        group = "test"
    elif column.startswith(_SHAPING_PREFIXES) or column.endswith("_ref_error"):
        group = "shaping"
    else:
        group = "misc"
    return f"{group}/{column}"


class EventWriter:
    """TensorBoard's own event-file writer with ``add_scalar`` and ``close``: the subset of
    ``torch.utils.tensorboard.SummaryWriter`` a run uses, without importing PyTorch (3-4 s at every run's first
    row, where nothing else a run does needs it). Hand-written only in the few lines below; the file format,
    the record writing and the flushing thread are the ``tensorboard`` package's."""

    def __init__(self, root: str | Path, purge_step: int):
        from tensorboard.compat.proto.event_pb2 import Event, SessionLog
        from tensorboard.compat.proto.summary_pb2 import Summary
        from tensorboard.summary.writer.event_file_writer import EventFileWriter

        self._event, self._summary = Event, Summary
        self._writer = EventFileWriter(str(root), max_queue_size=10, flush_secs=120)
        # what SummaryWriter(purge_step=...) writes: TensorBoard hides every older event at or past this step
        self._writer.add_event(Event(step=purge_step, file_version="brain.Event:2"))
        self._writer.add_event(Event(step=purge_step, session_log=SessionLog(status=SessionLog.START)))

    def add_scalar(self, tag: str, value: float, step: int) -> None:
        summary = self._summary(value=[self._summary.Value(tag=tag, simple_value=float(value))])
        self._writer.add_event(self._event(summary=summary, wall_time=time.time(), step=int(step)))

    def flush(self) -> None:
        self._writer.flush()

    def close(self) -> None:
        self._writer.close()


def open_writer(root: str | Path, first_row: dict) -> EventWriter:
    """An event writer on ``root`` whose events from ``first_row``'s env steps on are purged
    (a resumed run rewrites the generations after its checkpoint; env steps grow every generation)."""
    return EventWriter(root, purge_step=int(first_row["env_steps"]))


def log_row(writer, row: dict) -> None:
    """Every finite numeric value of ``row`` as ``tb_tag(column)`` at step ``row["env_steps"]``."""
    step = int(row["env_steps"])
    for k, v in row.items():
        if isinstance(v, numbers.Real) and math.isfinite(v):
            writer.add_scalar(tb_tag(k), v, step)
