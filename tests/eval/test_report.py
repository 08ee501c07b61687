"""The evaluation report on a folder of real parts, logged to a real MLflow server."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys

import pandas as pd
import pytest

from eval.searches import Search, folder_targets, run_searches
from eval.tracking import metric_name
from zonegraph.configs import InferConfig
from zonegraph.network.checkpoint import SHIPPED
from zonegraph.testing import requires_samples
from zonegraph.testing.mlflow_server import mlflow_server, rest, search_runs

pytestmark = pytest.mark.slow  # each test runs searches on real parts and an MLflow server

PARTS = ["Couch.json", "Pattern4-SteppedStartEndFace_17dd857d_0000.json"]


@requires_samples
def test_searches_are_isolated_recorded_and_resumed(samples_dir, tmp_path):
    shutil.copy(samples_dir / "Couch.json", tmp_path / "Couch.json")
    (tmp_path / "broken.step").write_text("not a STEP file")
    targets = folder_targets(tmp_path)
    assert [(t.design_id, t.gt_length) for t in targets] == [("Couch", 2), ("broken", None)]
    searches = [Search("heuristic", InferConfig(budget_s=2), t) for t in targets]
    first = run_searches(searches, tmp_path / "records", workers=2, timeout_s=120)
    couch = first.set_index("design_id").loc["Couch"]
    assert couch["outcome"] == "ok" and couch["exact"] and couch["trace"][-1][1] == 1.0
    broken = first.set_index("design_id").loc["broken"]
    assert broken["outcome"] == "invalid_input" and "corrupt" in broken["reason"] and not broken["exact"]
    again = run_searches(searches, tmp_path / "records", workers=2, timeout_s=120)
    assert again["time_to_best_s"].equals(first["time_to_best_s"])  # reused, not searched again
    other = [Search("heuristic", InferConfig(budget_s=2, k=1), targets[0])]
    assert run_searches(other, tmp_path / "records")["k"].tolist() == [1]  # other settings: a new record
    for name in ("a.pt", "b.pt"):  # the same weights at two paths: one record
        shutil.copy(SHIPPED, tmp_path / name)
    net = [
        Search("net", InferConfig(guide="net", budget_s=2, model=str(tmp_path / f"{n}.pt")), targets[0])
        for n in "ab"
    ]
    assert net[0].fingerprint() == net[1].fingerprint() != searches[0].fingerprint()


@requires_samples
def test_report_on_a_folder_is_an_mlflow_run_with_metrics_and_plots(samples_dir, tmp_path):
    parts = tmp_path / "parts"
    parts.mkdir()
    for name in PARTS:
        shutil.copy(samples_dir / name, parts / name)
    with mlflow_server(tmp_path) as url:
        rest(url, "experiments/search", {"max_results": 1})  # the server is up
        proc = subprocess.run(
            [sys.executable, "-m", "eval.report", "--designs", str(parts), "--budget", "2"]
            + [
                "--k",
                "1",
                "5",
                "--ablation-designs",
                "1",
                "--min-gt-length",
                "1",
                "--out",
                str(tmp_path / "out"),
            ],
            capture_output=True,
            text=True,
            env={**os.environ, "MLFLOW_TRACKING_URI": url},
            timeout=600,
        )
        assert proc.returncode == 0, proc.stderr[-2000:]
        [run] = search_runs(url, "evaluation")
        metrics = {m["key"]: m["value"] for m in run["data"]["metrics"]}
        files = rest(url, f"artifacts/list?run_id={run['info']['run_id']}")["files"]
    assert metrics["exact_at_1s/heuristic"] == 1.0 and 0 <= metrics["iou_at_1s/random"] <= 1
    assert {"report.md", "iou_time.png", "k_ablation.png", "curves.csv"} <= {f["path"] for f in files}
    curves = pd.read_csv(tmp_path / "out" / "curves.csv")
    assert set(curves["guide"]) == {"random", "heuristic"} and set(curves["k"]) == {1, 5}
    report = (tmp_path / "out" / "report.md").read_text()
    assert "rank needs the labels stage" in report
    strips = sorted(p.name for p in (tmp_path / "out").glob("strip_*.png"))
    assert strips and all(f"({name})" in report for name in strips)  # GT and heuristic side by side
    written = json.loads((tmp_path / "out" / "metrics.json").read_text())
    assert {metric_name(k): v for k, v in written.items()} == {
        metric_name(k): metrics[metric_name(k)] for k in written
    }
    assert {"iou_vs_ms/heuristic_k1", "exact_vs_ms/random_k5"} <= set(metrics)  # the curves, by search time
    assert run["info"]["run_name"].startswith("evaluate ")
