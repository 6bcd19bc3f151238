"""The benchmark of the paper's Fig. 4/5: every (method, seed) run resumably, across-seed statistics and a
Markdown report (``runner.py``, ``summary.py``, ``markdown.py``; CLI handlers in ``cli_commands.py``).

Not to be confused with ``shaped_es.speed`` (speed benchmarks: ``shaped-es speed``).
"""
