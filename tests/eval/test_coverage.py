"""The coverage taxonomy on design rows as the ground_truth stage writes them."""

from __future__ import annotations

import pandas as pd

from eval.coverage import CATEGORIES, category, coverage_table, plot_coverage, to_markdown

OK = {"convert_status": "ok", "replay_status": "ok", "graph_status": "ok", "simplified_status": "ok"}


def _row(folder: str = "01_2ops", **fields) -> dict:
    return {"folder": folder, "operations": "new_body,cut", **OK, **fields}


ROWS = {
    "gt_captured": _row(simplified_captured_l1=True, simplified_reaches_target=True),
    "other_sequence": _row(simplified_search_exact=True, simplified_reaches_target=True),
    "reachable_without_gt": _row(simplified_search_exact=True, simplified_reaches_target=False),
    "not_reconstructed": _row(simplified_search_exact=False, simplified_reaches_target=True),
    "zone_graph_failed": _row(graph_status="fuse_failed"),
    "unsupported": _row("02_3ops", operations="new_body,intersect", simplified_search_exact=False),
    "conversion_or_replay_failed": _row(convert_status="model_raised"),
    "timeout_or_crash": _row("02_3ops", simplified_status="timeout"),
}


def test_every_category_has_its_rule():
    for expected, row in ROWS.items():
        assert category(pd.Series(row), "simplified", 1) == expected


def test_table_markdown_and_plot(tmp_path):
    designs = pd.DataFrame(list(ROWS.values()))
    table = coverage_table(designs)
    assert list(table.index) == list(CATEGORIES) and (table["all"] == 1).all()
    assert table.loc["unsupported", "02_3ops"] == 1 and table.loc["unsupported", "01_2ops"] == 0
    text = to_markdown({"simplified graph, level 1": table})
    assert "| designs | 8 | 6 | 2 |" in text and "reconstructable with the GT sequence | 1 (12.5%)" in text
    assert plot_coverage(table, tmp_path / "c.png", "t").stat().st_size > 1000
