"""Results pages draw their tables from the committed figure files, never from typed numbers."""

import importlib.util
import json
from pathlib import Path

import pytest

from bench.figures import corpus_figure

ROOT = Path(__file__).resolve().parents[2]


def _hook():
    spec = importlib.util.spec_from_file_location("figures_hook", ROOT / "docs/hooks/figures.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_corpus_figure_counts_converted_searched_and_exact_designs():
    rows = [
        {
            "design_id": "a",
            "folder": "01",
            "status": "exact",
            "exact": True,
            "iou_zone": 1.0,
            "iou_brep": 1.0,
            "json_iou": 1.0,
            "script_iou": 1.0,
            "search_s": 1.0,
            "config": {"budget_s": 20},
        },
        {
            "design_id": "b",
            "folder": "01",
            "status": "rebuild_failed",
            "exact": False,
            "iou_zone": 1.0,
            "iou_brep": 0.5,
            "search_s": 22.0,
            "config": {"budget_s": 20},
        },
        {"design_id": "c", "folder": "02", "status": "convert_mismatch"},
        {"design_id": "d", "folder": "02", "status": "fuse_failed"},
    ]
    f = corpus_figure(rows)
    assert f["all"] == {"drawn": 4, "converted": 3, "zone_graph": 2, "exact": 1, "mean_iou_brep": 0.75}
    assert f["folders"]["02"]["converted"] == 1 and f["folders"]["02"]["exact"] == 0
    assert f["largest_overrun"] == pytest.approx(0.1)
    assert f["zone_exact"] == 2 and f["zone_exact_files_not_exact"] == ["b"]


def test_every_figure_marker_in_the_docs_renders_from_a_committed_file():
    hook = _hook()
    pages = [p for p in (ROOT / "docs").rglob("*.md") if "<!-- figure:" in p.read_text()]
    assert pages, "no page draws a figure"
    for page in pages:
        out = hook.render(page.read_text())
        assert "<!-- figure:" not in out and "Measured by:" in out, page


def test_a_missing_figure_file_stops_the_build():
    with pytest.raises(ValueError, match="does not exist"):
        _hook().render("<!-- figure: corpus-exact no-such-run -->")
    name = next((ROOT / "docs/figures").glob("*.json")).stem
    assert json.loads((ROOT / "docs/figures" / f"{name}.json").read_text())["command"]
