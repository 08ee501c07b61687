"""The ground_truth stage's design rows say why a design has no ground truth; its coverage tables."""

from __future__ import annotations

import pandas as pd

from pipelines.ground_truth import graph_results, write_coverage


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


def test_the_coverage_names_the_full_graph_only_where_the_stage_built_it(tmp_path):
    designs = pd.DataFrame(
        {
            "design_id": ["a", "b"],
            "folder": ["01_2ops", "01_2ops"],
            "graph_status": ["ok", "ok"],
            "simplified_status": ["ok", "ok"],
            "simplified_captured_l1": [True, False],
            "full_status": [None, None],
            "gt_seconds": [0.1, 0.2],
        }
    )
    files = (tmp_path / "coverage.png", tmp_path / "metrics.json", tmp_path / "details.json")
    write_coverage(designs, (1,), tmp_path, *files, full_graph=False)
    text = (tmp_path / "coverage.md").read_text()
    assert "simplified graph, level 1" in text and "full graph" not in text
    write_coverage(designs, (1,), tmp_path, *files, full_graph=True)
    assert "full graph, level 1" in (tmp_path / "coverage.md").read_text()
