"""Evaluation: relative GT rank, IoU vs time curves, coverage tables, plots and the MLflow report.

Run from the checkout (``python -m eval.report``, the DVC ``evaluate`` stage); not installed.
"""
