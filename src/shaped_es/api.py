"""Start a run from Python, as ``shaped-es train`` does, with callbacks (``shaped_es.train``).

.. code-block:: python

    from shaped_es import train

    def report(row):                              # after every generation's metrics row
        print(row["generation"], row["test_reward_mean"])
        return row["test_reward_mean"] is None or row["test_reward_mean"] < 200   # False stops the run

    rows = train({"env": "CarNav-v0", "method": "shaped", "generations": 60}, "runs/cb", callback=report)

The config is a :class:`shaped_es.config.RunConfig`, a dict of its fields (dotted keys allowed, as
``--set``) or the path of a YAML file; everything is checked before anything is written, as for
``train``. ``callback``: a function or :class:`shaped_es.monitor.callbacks.Callback`, or a list of them.
With the process executor (the default), a script must call ``train`` under ``if __name__ ==
"__main__":`` (its workers import the script again); unguarded, it ends with one line saying so and
exit code 2, before anything is written (``executors/main_guard.py``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from shaped_es.config import RunConfig, build_config, merge, read_yaml
from shaped_es.rundir.store import RunStore


def as_config(config: RunConfig | dict[str, Any] | str | Path) -> RunConfig:
    """``config`` as a validated :class:`RunConfig` (a dict may use dotted keys; a path is YAML)."""
    if isinstance(config, RunConfig):
        return config
    if isinstance(config, (str, Path)):
        config = read_yaml(config)
    return build_config(merge({}, dict(config)))


def prepare_run(cfg: RunConfig, out: str | Path):
    """The new run's store and env probe, once every check has passed; nothing is written before.
    Raises the one-line errors of ``shaped-es train`` (an ``out`` holding a run, a config that cannot start)."""
    from shaped_es.preflight import check_run

    store = RunStore(out)
    store.check_new()  # "already holds a run" / "not a directory" / a folder of other files / an empty path
    return store, check_run(cfg)  # everything is validated before anything is written


def train(config: RunConfig | dict[str, Any] | str | Path, out: str | Path, *, callback=None,
          progress: bool = False) -> list[dict]:
    """Train a new run into ``out`` (see the module docstring); returns its metrics rows."""
    from shaped_es.executors.main_guard import exit_if_unguarded, refuse_in_worker
    from shaped_es.methods import METHODS, resolve

    refuse_in_worker()  # a worker re-importing an unguarded script: never a second run
    cfg = as_config(config)
    if cfg.executor == "process" and METHODS[cfg.method].strategy is not None:  # workers re-import __main__
        exit_if_unguarded()  # one line naming the guard, exit 2, before anything is written
    store, probe = prepare_run(cfg, out)
    with store.lock():  # one writer; creates the directory (a failed start leaves it retryable)
        store.create(cfg)  # checks again, under the lock, that no other train got there first
        from shaped_es.trained.video import with_video

        return resolve(METHODS[cfg.method].train)(cfg, store, progress=progress, probe=probe,
                                                  callback=with_video(cfg, callback, progress))
