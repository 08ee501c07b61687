"""The stages from generate to labels on a real-data folder, as a user with r1.0.1 would run them."""

from __future__ import annotations

import json

import pandas as pd
import pyarrow.dataset as ds
import pytest
import yaml

from zonegraph.testing.stages import run_stage

pytestmark = pytest.mark.slow  # a pipeline run, stage by stage, in fresh interpreters


def test_stages_on_the_real_samples_folder(samples_dir, tmp_path):
    params = {
        "data": {
            "source": "fusion_json",
            "fusion_json_dir": str(samples_dir),
            "split_seed": 0,
            "test_fraction": 0.2,
        },
        "synthetic": {"count": 0, "seed": 0, "timeout_s": 60},
        "dask": {"scheduler": None, "n_workers": 2},
        "replay": {"timeout_s": 60},
        "zonegraph": {"simplify": True, "samples": 16, "seed": 0, "timeout_s": 120},
        "ground_truth": {"levels": [1, 3], "full_graph": True, "budget_s": 0.5, "timeout_s": 120},
        "labels": {
            "splits": ["train"],
            "rank_splits": ["test"],
            "limit": None,
            "limit_seed": 0,
            "level": 1,
            "multiplier": 1.0,
            "slack": 2,
            "seed": 0,
            "timeout_s": 120,
        },
    }
    (tmp_path / "params.yaml").write_text(yaml.safe_dump(params))
    assert "22 designs" in run_stage("pipelines.generate", tmp_path)
    assert "22/22 designs ok" in run_stage("pipelines.replay", tmp_path)
    manifest = pd.read_parquet(tmp_path / "data/replay/manifest.parquet")
    assert set(manifest["status"]) == {"ok"} and manifest["volume_rel_error"].max() < 1e-6
    couch = manifest.set_index("design_id").loc["Couch"]
    assert (couch.steps, couch.operations, couch.faces) == (2, "new_body,cut", 13)
    assert (tmp_path / "data/replay/breps/Couch/01_tool.brep").is_file()
    # A re-run reuses every finished design.
    assert "22 of 22 designs already done" in run_stage("pipelines.replay", tmp_path)

    # Zone graphs, the ground truth and labels.
    run_stage("pipelines.zonegraphs", tmp_path)
    assert "ground_truth: 22 designs" in run_stage("pipelines.ground_truth", tmp_path)
    gt = pd.read_parquet(tmp_path / "data/gt/designs.parquet").set_index("design_id")
    assert gt.loc["Couch", "simplified_captured_l1"] and gt.loc["Couch", "simplified_reaches_target"]
    out = run_stage("pipelines.labels", tmp_path)
    assert "labels:" in out
    proposals = ds.dataset(tmp_path / "data/labels/proposals").to_table().to_pandas()
    steps = ds.dataset(tmp_path / "data/labels/steps").to_table().to_pandas()
    assert "Couch" in set(proposals["design_id"])
    per_step = proposals.groupby(["design_id", "step"])["label"]
    assert (per_step.apply(lambda x: (x == 1).sum()) == 1).all()
    assert steps["captured"].sum() == len(per_step)
    # The test split is labelled rank-only: every proposal, the GT flagged, no completions.
    ranked = proposals[proposals["split"] == "test"]
    assert len(ranked) and (ranked["completions"] == 0).all() and ranked["label"].isin([0, 1]).all()
    trained = proposals[proposals["split"] == "train"]
    assert (trained["completions"] >= 1).any() and (trained["label"] == -1).any()
    metrics = json.loads((tmp_path / "data/details/labels.json").read_text())
    assert metrics["rank_only"]["labelled"] == ranked["design_id"].nunique()
    assert metrics["labelled"] == trained["design_id"].nunique() and metrics["rank_only"]["completions"] == 0
    # An interrupted run resumes: the finished designs are kept, the lost one recomputed, equal.
    (tmp_path / "data/labels/records/Couch.json").unlink()
    (tmp_path / "data/labels/proposals/Couch.parquet").unlink()
    assert "already done, resuming" in run_stage("pipelines.labels", tmp_path)
    again = ds.dataset(tmp_path / "data/labels/proposals").to_table().to_pandas()
    pd.testing.assert_frame_equal(
        again.sort_values(["design_id", "step", "zones"], key=lambda c: c.astype(str)).reset_index(drop=True),
        proposals.sort_values(["design_id", "step", "zones"], key=lambda c: c.astype(str)).reset_index(
            drop=True
        ),
    )
