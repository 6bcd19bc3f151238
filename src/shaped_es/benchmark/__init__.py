"""The benchmark of the paper's Fig. 4/5: every (method, seed) run resumably (``runner.py``; its settings and
its runs' configs in ``spec.py``, what a rerun reuses in ``plan.py``), across-seed statistics (``summary.py``)
and a Markdown report (``markdown.py``); the ``benchmark`` command's parser and handler in
``cli_commands.py``. ``shaped-es report`` (in ``cli/commands.py``) draws the same figures
and page for any runs.

Not to be confused with ``shaped_es.speed`` (speed benchmarks: ``shaped-es speed``).
"""
