"""Benchmarks: commands that print figures (JSON), never timed tests."""
