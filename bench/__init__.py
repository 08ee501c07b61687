"""Benchmarks: measured figures, printed; never timed tests."""
