"""The ground_truth stage's design rows say why a design has no ground truth."""

from __future__ import annotations

import pandas as pd

from pipelines.ground_truth import graph_results


def test_a_failed_job_gives_each_graph_its_status_and_reason():
    records = pd.DataFrame(
        [
            {
                "design_id": "a",
                "status": "ok",
                "reason": "",
                "seconds": 0.5,
                "simplified_status": "ok",
                "simplified_reason": None,
            },
            {
                "design_id": "b",
                "status": "invalid_input",
                "reason": "corrupt zone graph: negative zone volume",
                "seconds": 1.6,
                "simplified_status": None,
                "simplified_reason": None,
            },
        ]
    )
    rows = graph_results(records).set_index("design_id")
    assert rows.loc["b", "simplified_status"] == "invalid_input"
    assert rows.loc["b", "simplified_reason"] == "corrupt zone graph: negative zone volume"
    assert rows.loc["b", "full_reason"] == "corrupt zone graph: negative zone volume"
    assert rows.loc["a", "simplified_status"] == "ok" and rows.loc["a", "gt_seconds"] == 0.5
    assert "status" not in rows and "reason" not in rows
