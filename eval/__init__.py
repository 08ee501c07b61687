"""Evaluation: relative GT rank, IoU vs time curves, coverage tables, plots and reports (planned)."""
