"""The DVC metrics files share their keys, so ``dvc metrics show`` stays a narrow table; the
breakdowns land in the details files beside them."""

from __future__ import annotations

import json
from pathlib import Path

import pandas as pd
import pytest

from eval.dvc_metrics import HEADLINE, SHARED, headline, median, write_guides
from eval.report import guide_metrics
from pipelines import generate, reconstruct, replay, zonegraphs


def write_small_metrics(root: Path) -> None:
    """Each stage's metrics and details from a few designs' rows, as the stages write them."""
    m, d = root / "data/metrics", root / "data/details"
    statuses = ["ok", "ok", "ok", "convert_timeout"]
    conversion = pd.DataFrame(
        {
            "design_id": list("abcd"),
            "folder": ["01_2ops", "01_2ops", "02_3ops", "02_3ops"],
            "status": statuses,
            "reason": ["", "", "", "took too long"],
            "seconds": [1.0, 2.0, 3.0, 60.0],
        }
    )
    (root / "designs").mkdir(parents=True, exist_ok=True)
    generate.write_conversion(conversion, root / "designs", m / "conversion.json", d / "conversion.json")
    manifest = pd.DataFrame(
        {
            "design_id": list("abc"),
            "status": ["ok", "ok", "replay_failed"],
            "reason": ["", "", "a bad extrude"],
            "seconds": [0.5, 0.25, 0.1],
            "job_seconds": [0.5, 0.25, None],  # the zone graphs' manifest's name
            "volume_rel_error": [1e-12, 2e-12, None],
            "build_s": [0.2, 0.1, None],
            "zones": [8, 12, None],
        }
    )
    replay.write_metrics(manifest, {"retry_limit": 3}, m / "replay.json", d / "replay.json")
    zonegraphs.write_metrics(manifest, m / "zonegraphs.json", d / "zonegraphs.json")
    results = pd.DataFrame(
        {
            "design_id": ["a", "b", "a", "b"],
            "guide": ["heuristic", "heuristic", "random", "random"],
            "status": ["exact", "partial", "partial", "timeout"],
            "exact": [True, False, False, False],
            "iou_brep": [1.0, 0.5, 0.25, None],
            "time_to_best_s": [0.4, 1.0, 2.0, None],
            "seconds": [1.0, 2.0, 2.0, 60.0],
        }
    )
    reconstruct.write_metrics(reconstruct.summarise(results), m / "reconstruct", d / "reconstruct.json")


def _read(path: Path) -> dict:
    return json.loads(path.read_text())


def test_every_metrics_file_has_the_shared_keys_and_no_others(tmp_path):
    write_small_metrics(tmp_path)
    m, d = tmp_path / "data/metrics", tmp_path / "data/details"
    metrics = [*m.glob("*.json"), *m.glob("*/*.json")]  # dvc metrics show data/metrics: these only
    assert {f.stem for f in metrics} == {"conversion", "replay", "zonegraphs", "heuristic", "random"}
    for f in metrics:
        assert set(SHARED) <= set(_read(f)) <= {*SHARED, *HEADLINE}, f
    assert _read(m / "conversion.json") == {"designs": 4, "ok": 3, "failed": 1, "seconds": 2.5}
    assert _read(d / "conversion.json")["by_folder"]["02_3ops"] == {"designs": 2, "converted": 1}
    assert _read(d / "replay.json")["failed_by_status"] == {"replay_failed": 1}
    assert _read(d / "zonegraphs.json")["median_zones"] == 10.0
    # The exact rate and mean IoU count every design of the guide, the failed searches as 0.
    assert _read(m / "reconstruct/heuristic.json") == {
        "designs": 2,
        "ok": 2,
        "failed": 0,
        "seconds": 1.5,
        "exact": 0.5,
        "iou": 0.75,
    }
    assert _read(m / "reconstruct/random.json")["failed"] == 1
    assert _read(d / "reconstruct.json")["random"]["failures"] == {"timeout": 1}


def test_a_guide_no_longer_run_loses_its_file(tmp_path):
    write_guides(tmp_path, {"net:shipped": {"designs": 1}, "heuristic": {"designs": 1}})
    write_guides(tmp_path, {"heuristic": {"designs": 2}})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["heuristic.json"]
    write_guides(tmp_path, {"net:shipped": {"designs": 1}})
    assert sorted(p.name for p in tmp_path.iterdir()) == ["net_shipped.json"]


def test_the_evaluation_metrics_are_read_at_the_end_of_the_budget():
    curve = pd.DataFrame(
        {
            "guide": ["heuristic"] * 2 + ["random"] * 2,
            "k": 5,
            "seconds": [1.0, 2.0, 1.0, 2.0],
            "mean_iou": [0.5, 0.9, 0.25, 0.5],
            "exact_rate": [0.0, 0.5, 0.0, 0.25],
            "designs": 4,
        }
    )
    rank = pd.DataFrame({"guide": ["heuristic", "random"], "rank": [0.12345, 0.5]})
    assert guide_metrics(rank, curve) == {
        "heuristic": {"designs": 4, "exact": 0.5, "iou": 0.9, "rank": 0.123},
        "random": {"designs": 4, "exact": 0.25, "iou": 0.5, "rank": 0.5},
    }


def test_headline_rejects_a_key_outside_the_shared_set():
    assert median([None, 3.0, float("nan"), 1.0]) == 2.0
    with pytest.raises(ValueError, match="not headline metrics"):
        headline(1, 1, (), exact_rate=1.0)
