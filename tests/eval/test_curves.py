"""IoU-vs-time curves from anytime traces: step functions, B-rep endings, exact rates."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from eval.curves import curves, iou_at, plot_curves, time_grid


def test_a_trace_is_a_step_function_that_ends_at_the_brep_iou():
    trace = [(0.0, 0.2), (0.5, 0.6), (2.0, 1.0)]
    times = np.array([0.1, 0.5, 1.0, 3.0])
    assert iou_at(trace, times).tolist() == [0.2, 0.6, 0.6, 1.0]
    assert iou_at(trace, times, final_iou=0.97).tolist() == [0.2, 0.6, 0.6, 0.97]
    assert iou_at([(0.3, 0.5)], np.array([0.1, 0.3])).tolist() == [0.0, 0.5]
    assert iou_at([], times).tolist() == [0.0] * 4


def test_curves_average_designs_and_count_exact_only_when_found():
    results = pd.DataFrame(
        [
            {
                "guide": "h",
                "trace": [(0.0, 0.0), (1.0, 1.0)],
                "iou_brep": 1.0,
                "exact": True,
                "time_to_best_s": 1.0,
            },
            {"guide": "h", "trace": [(0.0, 0.5)], "iou_brep": 0.5, "exact": False, "time_to_best_s": 0.0},
            {"guide": "h", "trace": None, "iou_brep": np.nan, "exact": False, "time_to_best_s": np.nan},
        ]
    )
    table = curves(results, np.array([0.5, 2.0]))
    assert table["mean_iou"].tolist() == pytest.approx([0.5 / 3, 1.5 / 3])
    assert table["exact_rate"].tolist() == pytest.approx([0.0, 1 / 3])
    assert (table["designs"] == 3).all()


def test_grid_and_plot(tmp_path):
    grid = time_grid(20.0, 5)
    assert grid[0] == pytest.approx(1e-3) and grid[-1] == pytest.approx(20.0) and np.all(np.diff(grid) > 0)
    table = pd.DataFrame({"guide": "h", "seconds": grid, "mean_iou": grid / 20, "exact_rate": grid / 40})
    assert plot_curves(table, tmp_path / "c.png").stat().st_size > 1000
