"""Weights & Biases logging of a run (``--wandb``; ``pip install 'shaped-es[wandb]'``): every
``metrics.csv`` row under the TensorBoard tags (``GROUP/column``, :func:`shaped_es.monitor.tensorboard.tb_tag`), with
``misc/env_steps`` as every chart's x axis, as TensorBoard's step.

The W&B run's id is kept in ``RUN/wandb_id``, so ``resume`` continues the same W&B run (the rows a
killed run wrote after its last checkpoint are logged again: W&B keeps both). W&B's own console output
is silenced: the run's progress display says, in one line, where the W&B run goes. ``mode`` ``offline``
(or ``WANDB_MODE=offline``) needs no network or account: the run is written under ``RUN/wandb/`` for a
later ``wandb sync``.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable
from pathlib import Path

from shaped_es.monitor.tensorboard import tb_tag

STEP = tb_tag("env_steps")  # "misc/env_steps": the x axis of every chart
ID_FILE = "wandb_id"


def open_run(root: str | Path, settings, config: dict, write_text: Callable[[Path, str], None]):
    """A W&B run for the run directory ``root`` (``settings``: the config's ``wandb`` section), resuming
    the one whose id ``root/wandb_id`` holds; a new id is written with ``write_text(path, text)`` (the run
    directory's atomic write: this module knows nothing of the run directory)."""
    import wandb

    root = Path(root)
    id_path = root / ID_FILE
    run_id = id_path.read_text().strip() if id_path.is_file() else None
    if not run_id:
        import secrets

        run_id = secrets.token_hex(8)  # W&B ids: letters and digits
        write_text(id_path, run_id + "\n")
    run = wandb.init(project=settings.project, entity=settings.entity, group=settings.group,
                     name=root.name, id=run_id, resume="allow", dir=str(root), config=config,
                     mode=settings.mode, settings=wandb.Settings(silent=True, console="off"))
    run.define_metric(STEP)
    run.define_metric("*", step_metric=STEP)
    return run


def where(run) -> str:
    """Where the W&B run goes, in words: its URL, or the ``wandb sync`` command of an offline run."""
    if getattr(run, "offline", False):
        return f"offline, written to {run.settings.sync_dir} (upload later: wandb sync {run.settings.sync_dir})"
    return str(run.url)


def log_row(run, row: dict) -> None:
    """Every finite numeric value of ``row`` as ``tb_tag(column)`` (``None`` and NaN cells left out)."""
    data = {tb_tag(k): v for k, v in row.items()
            if isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v)}
    run.log(data)
