"""The generate and replay stages on a real-data folder, as a user with r1.0.1 would run them."""

from __future__ import annotations

import subprocess
import sys

import pandas as pd
import yaml


def run_stage(module: str, cwd) -> str:
    proc = subprocess.run(
        [sys.executable, "-m", module], cwd=cwd, capture_output=True, text=True, timeout=600
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


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
