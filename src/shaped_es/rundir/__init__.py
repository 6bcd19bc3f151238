"""The run directory: what a run owns on disk and how it is written.

``store.py`` the run directory (``RunStore``: config, metrics, checkpoints, trajectory shards);
``checkpoints.py`` its checkpoints (saved, found, loaded if they are the run's own); ``recovery.py``
what resume repairs after a kill;
``atomic.py`` its error types and atomic writes; ``lock.py`` one writer per run (the directory
``flock``-ed and ``RUN/.lock``); ``metrics_csv.py`` reading, appending and repairing ``RUN/metrics.csv``;
``meta.py`` what every checkpoint records about its run (counters, config digest), ES or PPO;
``prune.py`` what ``shaped-es prune`` deletes from a finished run (what only an exact resume reads) and
the mark that makes resume refuse it.
"""
