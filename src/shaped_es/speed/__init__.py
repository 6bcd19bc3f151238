"""Speed benchmarks (``shaped-es speed``, alias ``bench``): commands that print figures (JSON), never timed tests."""
