"""Issue 14's fuzz suite through the pipeline: mutated designs (the fuzz harness's strategies,
seeded) beside a few good ones go through generate, replay and zonegraphs; every stage completes,
every design is exactly one manifest row, a failure has a status and a reason, the good designs
succeed."""

from __future__ import annotations

import shutil

import pandas as pd
import pytest
import yaml

from zonegraph.testing.fuzz import mutated_designs
from zonegraph.testing.stages import run_stage

pytestmark = pytest.mark.slow  # a pipeline run, stage by stage, in fresh interpreters

GOOD = ("SingleSketchExtrude", "Couch", "Hexagon")
MUTATED, SEED = 24, 0
STAGES = {"replay": "reason", "zonegraphs": "reason"}  # each manifest's name for a failure's reason


def _params(designs) -> dict:
    return {
        "data": {
            "source": "fusion_json",
            "fusion_json_dir": str(designs),
            "split_seed": 0,
            "test_fraction": 0.2,
        },
        "synthetic": {"count": 0, "seed": 0, "timeout_s": 60},
        "dask": {"scheduler": None, "n_workers": 2},
        "replay": {"timeout_s": 20},
        "zonegraph": {"simplify": True, "samples": 16, "seed": 0, "timeout_s": 60},
    }


def test_mutated_designs_become_manifest_rows(samples_dir, tmp_path):
    designs = tmp_path / "designs"
    designs.mkdir()
    for name in GOOD:
        shutil.copy(samples_dir / f"{name}.json", designs)
    labels = {}
    for i, (label, data) in enumerate(mutated_designs(MUTATED, SEED)):
        labels[f"fuzz{i:02d}"] = label
        (designs / f"fuzz{i:02d}.json").write_bytes(data)
    (tmp_path / "params.yaml").write_text(yaml.safe_dump(_params(designs)))
    ids = sorted([*GOOD, *labels])
    assert f"{len(ids)} designs" in run_stage("pipelines.generate", tmp_path)
    for stage, reason in STAGES.items():
        run_stage(f"pipelines.{stage}", tmp_path)
        manifest = pd.read_parquet(tmp_path / f"data/{stage}/manifest.parquet")
        assert sorted(manifest["design_id"]) == ids, stage
        failed = manifest[manifest["status"] != "ok"]
        no_reason = failed[failed[reason].fillna("").str.strip() == ""]
        assert no_reason.empty, f"{stage}: failures without a reason: " + ", ".join(
            f"{d} ({labels.get(d)}): {s}"
            for d, s in zip(no_reason["design_id"], no_reason["status"], strict=True)
        )
        statuses = manifest.set_index("design_id")["status"]
        assert (statuses[list(GOOD)] == "ok").all(), f"{stage}: {statuses[list(GOOD)].to_dict()}"
