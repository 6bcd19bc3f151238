"""What a finished (or running) run's saved policy is used for: ``load.py`` (``shaped_es.load_policy``,
the policy from Python), ``evaluate.py`` (``shaped-es evaluate``: fresh test episodes) and ``render.py``
(``shaped-es render``: a GIF). Per-method differences are hooks of ``methods.Method``.
"""
